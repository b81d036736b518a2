#include "slam/io/bag/sqlite_bag_writer.h"

#include <sqlite3.h>

#include <filesystem>
#include <stdexcept>

#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// One statement per table, as rosbag2_storage_sqlite3's sqlite_storage.cpp creates them.
constexpr const char* kCreateTables =
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);"
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,"
    "metadata TEXT NOT NULL);"
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
    "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL,"
    "type_description_hash TEXT NOT NULL);"
    "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY,topic_type TEXT NOT NULL,"
    "encoding TEXT NOT NULL,encoded_message_definition TEXT NOT NULL,"
    "type_description_hash TEXT NOT NULL);"
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
    "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
    "INSERT INTO schema(schema_version, ros_distro) VALUES (4, 'humble');";

}  // namespace

SqliteBagWriter::SqliteBagWriter(std::string path) : path_(std::move(path)) {
  std::filesystem::remove(path_);
  Check(sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr),
        "open");
  // The bag folder is made complete by a rename, so no journal is needed for atomicity.
  Exec("PRAGMA journal_mode=OFF;PRAGMA synchronous=OFF;");
  Exec(kCreateTables);
  Exec("BEGIN TRANSACTION;");
  Check(
      sqlite3_prepare_v2(db_, "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?);",
                         -1, &insert_, nullptr),
      "prepare");
}

SqliteBagWriter::~SqliteBagWriter() {
  if (insert_ != nullptr) sqlite3_finalize(insert_);
  if (db_ != nullptr) sqlite3_close(db_);
}

void SqliteBagWriter::Check(int rc, const char* what) {
  if (rc == SQLITE_OK || rc == SQLITE_DONE || rc == SQLITE_ROW) return;
  throw OutputError(path_ + ": sqlite3 " + what + ": " +
                    (db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(rc)));
}

void SqliteBagWriter::Exec(const char* sql) {
  char* message = nullptr;
  const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, &message);
  if (rc != SQLITE_OK) {
    const std::string text = message != nullptr ? message : sqlite3_errstr(rc);
    sqlite3_free(message);
    throw OutputError(path_ + ": sqlite3: " + text);
  }
}

std::int64_t SqliteBagWriter::AddTopic(std::string_view name, std::string_view type,
                                       std::string_view offered_qos_profiles,
                                       std::string_view definition) {
  const std::int64_t id = next_topic_id_++;
  sqlite3_stmt* st = nullptr;
  Check(sqlite3_prepare_v2(db_,
                           "INSERT INTO topics (id, name, type, serialization_format, "
                           "offered_qos_profiles, type_description_hash) "
                           "VALUES (?, ?, ?, 'cdr', ?, '');",
                           -1, &st, nullptr),
        "prepare");
  sqlite3_bind_int64(st, 1, id);
  sqlite3_bind_text(st, 2, name.data(), static_cast<int>(name.size()), SQLITE_TRANSIENT);
  sqlite3_bind_text(st, 3, type.data(), static_cast<int>(type.size()), SQLITE_TRANSIENT);
  sqlite3_bind_text(st, 4, offered_qos_profiles.data(),
                    static_cast<int>(offered_qos_profiles.size()), SQLITE_TRANSIENT);
  const int rc = sqlite3_step(st);
  sqlite3_finalize(st);
  Check(rc, "insert topic");

  const std::string key = "\n" + std::string(type) + "\n";
  if (("\n" + types_with_definition_).find(key) == std::string::npos) {
    types_with_definition_ += std::string(type) + "\n";
    Check(sqlite3_prepare_v2(db_,
                             "INSERT INTO message_definitions (topic_type, encoding, "
                             "encoded_message_definition, type_description_hash) "
                             "VALUES (?, 'ros2msg', ?, '');",
                             -1, &st, nullptr),
          "prepare");
    sqlite3_bind_text(st, 1, type.data(), static_cast<int>(type.size()), SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, definition.data(), static_cast<int>(definition.size()),
                      SQLITE_TRANSIENT);
    const int rc2 = sqlite3_step(st);
    sqlite3_finalize(st);
    Check(rc2, "insert message definition");
  }
  return id;
}

void SqliteBagWriter::WriteMessage(std::int64_t topic_id, std::int64_t timestamp_ns,
                                   std::string_view data) {
  sqlite3_bind_int64(insert_, 1, timestamp_ns);
  sqlite3_bind_int64(insert_, 2, topic_id);
  sqlite3_bind_blob(insert_, 3, data.data(), static_cast<int>(data.size()), SQLITE_STATIC);
  const int rc = sqlite3_step(insert_);
  sqlite3_reset(insert_);
  Check(rc, "insert message");
}

void SqliteBagWriter::Close(std::string_view metadata_yaml, int metadata_version) {
  sqlite3_stmt* st = nullptr;
  Check(sqlite3_prepare_v2(db_, "INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?);",
                           -1, &st, nullptr),
        "prepare");
  sqlite3_bind_int(st, 1, metadata_version);
  sqlite3_bind_text(st, 2, metadata_yaml.data(), static_cast<int>(metadata_yaml.size()),
                    SQLITE_TRANSIENT);
  const int rc = sqlite3_step(st);
  sqlite3_finalize(st);
  Check(rc, "insert metadata");
  sqlite3_finalize(insert_);
  insert_ = nullptr;
  Exec("COMMIT;");
  Check(sqlite3_close(db_), "close");
  db_ = nullptr;
}

}  // namespace slamrig::slam
