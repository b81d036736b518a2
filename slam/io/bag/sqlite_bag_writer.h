#pragma once

#include <cstdint>
#include <string>
#include <string_view>

struct sqlite3;
struct sqlite3_stmt;

namespace slamrig::slam {

/// Writes a rosbag2 sqlite3 storage file (`.db3`) with the tables rosbag2_storage_sqlite3
/// creates at schema version 4 (ROS 2 Iron and later):
///   schema(schema_version, ros_distro), metadata(id, metadata_version, metadata),
///   topics(id, name, type, serialization_format, offered_qos_profiles, type_description_hash),
///   messages(id, topic_id, timestamp, data), message_definitions(id, topic_type, encoding,
///   encoded_message_definition, type_description_hash), and the index on messages.timestamp.
/// All messages go in one transaction, committed by Close(). Throws std::runtime_error naming
/// the path and sqlite's message on failure.
class SqliteBagWriter {
 public:
  explicit SqliteBagWriter(std::string path);
  ~SqliteBagWriter();
  SqliteBagWriter(const SqliteBagWriter&) = delete;
  SqliteBagWriter& operator=(const SqliteBagWriter&) = delete;

  /// Adds a topic (and its type's message definition, once per type); returns its id.
  std::int64_t AddTopic(std::string_view name, std::string_view type,
                        std::string_view offered_qos_profiles, std::string_view definition);
  /// Inserts one CDR message.
  void WriteMessage(std::int64_t topic_id, std::int64_t timestamp_ns, std::string_view data);
  /// Stores `metadata_yaml` in the metadata table, commits and closes the database.
  void Close(std::string_view metadata_yaml, int metadata_version);

 private:
  void Exec(const char* sql);
  void Check(int rc, const char* what);

  std::string path_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_ = nullptr;
  std::int64_t next_topic_id_ = 1;
  std::string types_with_definition_;  // '\n'-joined
};

}  // namespace slamrig::slam
