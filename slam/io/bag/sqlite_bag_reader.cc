#include <sqlite3.h>

#include <map>

#include "slam/config/yaml_node.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

class Database {
 public:
  explicit Database(const std::string& path) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      Fail("open");
    }
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  [[noreturn]] void Fail(const std::string& what) const {
    throw ParseError(path_ + ": sqlite3 " + what + ": " +
                     (db_ != nullptr ? sqlite3_errmsg(db_) : "cannot open"));
  }

  sqlite3* get() const { return db_; }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
};

class Statement {
 public:
  Statement(const Database& db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db.get(), sql, -1, &st_, nullptr) != SQLITE_OK) db.Fail(sql);
  }
  ~Statement() { sqlite3_finalize(st_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  bool Step() {
    const int rc = sqlite3_step(st_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) db_.Fail("read");
    return false;
  }
  std::int64_t Int(int col) const { return sqlite3_column_int64(st_, col); }
  std::string Text(int col) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st_, col));
    return p != nullptr ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(st_, col)))
                        : std::string();
  }
  std::string Blob(int col) const {
    const auto* p = static_cast<const char*>(sqlite3_column_blob(st_, col));
    return p != nullptr ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(st_, col)))
                        : std::string();
  }

 private:
  const Database& db_;
  sqlite3_stmt* st_ = nullptr;
};

}  // namespace

RawBag ReadSqliteBagFile(const std::string& path) {
  Database db(path);
  RawBag bag;
  std::map<std::int64_t, std::size_t> topic_index;
  {
    Statement topics(db, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
    while (topics.Step()) {
      topic_index[topics.Int(0)] = bag.topics.size();
      bag.topics.push_back({topics.Text(1), topics.Text(2), topics.Text(3)});
    }
  }
  // rosbag2 keeps a copy of metadata.yaml here since schema version 3.
  bool has_metadata = false;
  {
    Statement table(db, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'metadata'");
    has_metadata = table.Step();
  }
  if (has_metadata) {
    Statement metadata(db, "SELECT metadata FROM metadata ORDER BY id DESC LIMIT 1");
    if (metadata.Step()) {
      try {
        const YamlNode root = YamlNode::LoadString(metadata.Text(0), path + ": metadata table");
        if (const auto info = root.Optional("rosbag2_bagfile_information")) {
          if (const auto custom = info->Optional("custom_data")) {
            for (const std::string& key : custom->Keys()) {
              bag.custom_data[key] = custom->Get<std::string>(key);
            }
          }
        }
      } catch (const ConfigError& e) {
        throw ParseError(e.what());
      }
    }
  }
  Statement messages(db, "SELECT id, topic_id, timestamp, data FROM messages ORDER BY id");
  while (messages.Step()) {
    const auto it = topic_index.find(messages.Int(1));
    if (it == topic_index.end()) {
      throw ParseError(path + ": messages row " + std::to_string(messages.Int(0)) + ": topic_id " +
                       std::to_string(messages.Int(1)) + " is not in topics");
    }
    bag.messages.push_back({it->second, messages.Int(2), messages.Blob(3)});
  }
  return bag;
}

}  // namespace slamrig::slam
