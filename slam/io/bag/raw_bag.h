#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace slamrig::slam {

/// One topic of a bag as its storage declares it.
struct RawBagTopic {
  std::string name;
  std::string type;      ///< e.g. "sensor_msgs/msg/LaserScan"; "" when the storage has none
  std::string encoding;  ///< "cdr" for rosbag2
};

/// One serialized message.
struct RawBagMessage {
  std::size_t topic = 0;  ///< index into RawBag::topics
  std::int64_t log_time_ns = 0;
  std::string data;
};

/// A bag's contents before decoding, in storage order.
struct RawBag {
  std::vector<RawBagTopic> topics;
  std::vector<RawBagMessage> messages;
  /// Writer's key-value notes: metadata custom_data (sqlite3's metadata table) or channel
  /// metadata entries named "slamrig.*" (MCAP).
  std::map<std::string, std::string> custom_data;
};

/// Reads an MCAP file, checking the magic at both ends, every record length, the CRC of every
/// chunk, of the data section and of the summary (where the file has one, i.e. non-zero), and
/// decompressing zstd and lz4 chunks. Throws ParseError naming the file, the byte offset and
/// what is wrong; never reads out of bounds.
RawBag ReadMcapFile(const std::string& path);

/// Reads a rosbag2 sqlite3 file (topics and messages tables, any schema version; custom_data
/// from the YAML in the metadata table when it has one). Throws
/// ParseError naming the file and sqlite's message, or the message id for a message whose
/// topic is missing.
RawBag ReadSqliteBagFile(const std::string& path);

}  // namespace slamrig::slam
