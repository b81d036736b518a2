#pragma once

#include <cstdint>
#include <map>
#include <optional>
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

/// How a file cut short (a recording killed mid-way) was read: up to where.
struct RawBagCut {
  /// Where reading stopped, for a note after the file name: "truncated at byte 3,000,000", or
  /// what sqlite3 could not read.
  std::string where;
  /// Every message is there: only what follows the messages (an MCAP summary) is missing.
  bool all_messages = false;
};

/// A bag's contents before decoding, in storage order.
struct RawBag {
  std::vector<RawBagTopic> topics;
  std::vector<RawBagMessage> messages;
  /// Writer's key-value notes: metadata custom_data (sqlite3's metadata table) or channel
  /// metadata entries named "slamrig.*" (MCAP).
  std::map<std::string, std::string> custom_data;
  /// Set when the file was cut short and read up to the cut (`recover_cut`): `messages` are
  /// then every message before the cut, in storage order.
  std::optional<RawBagCut> cut;
};

/// Reads an MCAP file, checking the magic at both ends, every record length, the CRC of every
/// chunk, of the data section and of the summary (where the file has one, i.e. non-zero), and
/// decompressing zstd and lz4 chunks. Throws ParseError naming the file, the byte offset and
/// what is wrong; never reads out of bounds.
/// A file without the closing magic (a writer killed mid-way) is a ParseError, or with
/// `recover_cut` is read record by record up to the first record that runs past the end: every
/// message of the complete chunks (and unchunked messages) before it, `cut` saying where.
/// Damage before the cut (a CRC mismatch, a chunk that does not decompress) stays an error.
RawBag ReadMcapFile(const std::string& path, bool recover_cut = false);

/// Reads a rosbag2 sqlite3 file (topics and messages tables, any schema version; custom_data
/// from the YAML in the metadata table when it has one). Throws
/// ParseError naming the file and sqlite's message, or the message id for a message whose
/// topic is missing. Reading past the end of the file is an error, never zeros.
/// A file shorter than its header says (cut short) is a ParseError, or with `recover_cut` is
/// read in message id order up to the first row sqlite3 cannot read (a page past the cut, a
/// damaged page): those rows, `cut` saying where; so is a whole-sized file whose message rows
/// stop being readable (a writer killed while writing pages).
RawBag ReadSqliteBagFile(const std::string& path, bool recover_cut = false);

}  // namespace slamrig::slam
