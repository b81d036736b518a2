#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>

#include "slam/config/yaml_node.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/io/dataset.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

namespace fs = std::filesystem;

// The VFS bags are opened with: the default one, except that reading the main database file
// past its end is an I/O error. sqlite3 itself reads a missing page as zeros, which a b-tree
// page of a cut file pointing past the end would turn into made-up rows or blob bytes; as an
// error, reading stops at the first row that needs a page the file does not have. A whole file
// never reads past its end, so it reads as with the default VFS.
constexpr const char* kVfsName = "slamrig-no-short-read";

struct ShimFile {
  sqlite3_file base;  // first: sqlite3 sees a ShimFile as a sqlite3_file
  sqlite3_file* real;
  bool main_db;
};

sqlite3_vfs g_vfs;

sqlite3_vfs* RealVfs() { return static_cast<sqlite3_vfs*>(g_vfs.pAppData); }
sqlite3_file* Real(sqlite3_file* f) { return reinterpret_cast<ShimFile*>(f)->real; }
const sqlite3_io_methods& RealMethods(sqlite3_file* f) { return *Real(f)->pMethods; }

int ShimRead(sqlite3_file* f, void* buffer, int n, sqlite3_int64 offset) {
  const int rc = RealMethods(f).xRead(Real(f), buffer, n, offset);
  return rc == SQLITE_IOERR_SHORT_READ && reinterpret_cast<ShimFile*>(f)->main_db
             ? SQLITE_IOERR_READ
             : rc;
}

const sqlite3_io_methods kShimMethods = {
    3,
    [](sqlite3_file* f) { return RealMethods(f).xClose(Real(f)); },
    ShimRead,
    [](sqlite3_file* f, const void* b, int n, sqlite3_int64 o) {
      return RealMethods(f).xWrite(Real(f), b, n, o);
    },
    [](sqlite3_file* f, sqlite3_int64 size) { return RealMethods(f).xTruncate(Real(f), size); },
    [](sqlite3_file* f, int flags) { return RealMethods(f).xSync(Real(f), flags); },
    [](sqlite3_file* f, sqlite3_int64* size) { return RealMethods(f).xFileSize(Real(f), size); },
    [](sqlite3_file* f, int lock) { return RealMethods(f).xLock(Real(f), lock); },
    [](sqlite3_file* f, int lock) { return RealMethods(f).xUnlock(Real(f), lock); },
    [](sqlite3_file* f, int* out) { return RealMethods(f).xCheckReservedLock(Real(f), out); },
    [](sqlite3_file* f, int op, void* arg) {
      return RealMethods(f).xFileControl(Real(f), op, arg);
    },
    [](sqlite3_file* f) { return RealMethods(f).xSectorSize(Real(f)); },
    [](sqlite3_file* f) { return RealMethods(f).xDeviceCharacteristics(Real(f)); },
    [](sqlite3_file* f, int page, int size, int extend, void volatile** out) {
      return RealMethods(f).iVersion >= 2 ? RealMethods(f).xShmMap(Real(f), page, size, extend, out)
                                          : SQLITE_IOERR;
    },
    [](sqlite3_file* f, int offset, int n, int flags) {
      return RealMethods(f).iVersion >= 2 ? RealMethods(f).xShmLock(Real(f), offset, n, flags)
                                          : SQLITE_IOERR;
    },
    [](sqlite3_file* f) {
      if (RealMethods(f).iVersion >= 2) RealMethods(f).xShmBarrier(Real(f));
    },
    [](sqlite3_file* f, int remove) {
      return RealMethods(f).iVersion >= 2 ? RealMethods(f).xShmUnmap(Real(f), remove) : SQLITE_OK;
    },
    [](sqlite3_file* f, sqlite3_int64 offset, int n, void** out) {
      if (RealMethods(f).iVersion >= 3) return RealMethods(f).xFetch(Real(f), offset, n, out);
      *out = nullptr;
      return SQLITE_OK;
    },
    [](sqlite3_file* f, sqlite3_int64 offset, void* p) {
      return RealMethods(f).iVersion >= 3 ? RealMethods(f).xUnfetch(Real(f), offset, p) : SQLITE_OK;
    },
};

int ShimOpen(sqlite3_vfs*, const char* name, sqlite3_file* file, int flags, int* out_flags) {
  auto* shim = reinterpret_cast<ShimFile*>(file);
  shim->real = reinterpret_cast<sqlite3_file*>(shim + 1);
  shim->main_db = (flags & SQLITE_OPEN_MAIN_DB) != 0;
  const int rc = RealVfs()->xOpen(RealVfs(), name, shim->real, flags, out_flags);
  shim->base.pMethods = shim->real->pMethods != nullptr ? &kShimMethods : nullptr;
  return rc;
}

// Registers the VFS once (thread-safe) and returns its name.
const char* NoShortReadVfs() {
  static std::once_flag once;
  std::call_once(once, [] {
    sqlite3_vfs* real = sqlite3_vfs_find(nullptr);
    g_vfs.iVersion = 2;
    g_vfs.szOsFile = static_cast<int>(sizeof(ShimFile)) + real->szOsFile;
    g_vfs.mxPathname = real->mxPathname;
    g_vfs.zName = kVfsName;
    g_vfs.pAppData = real;
    g_vfs.xOpen = ShimOpen;
    g_vfs.xDelete = [](sqlite3_vfs*, const char* name, int sync) {
      return RealVfs()->xDelete(RealVfs(), name, sync);
    };
    g_vfs.xAccess = [](sqlite3_vfs*, const char* name, int flags, int* out) {
      return RealVfs()->xAccess(RealVfs(), name, flags, out);
    };
    g_vfs.xFullPathname = [](sqlite3_vfs*, const char* name, int n, char* out) {
      return RealVfs()->xFullPathname(RealVfs(), name, n, out);
    };
    g_vfs.xDlOpen = [](sqlite3_vfs*, const char* name) {
      return RealVfs()->xDlOpen(RealVfs(), name);
    };
    g_vfs.xDlError = [](sqlite3_vfs*, int n, char* out) { RealVfs()->xDlError(RealVfs(), n, out); };
    g_vfs.xDlSym = [](sqlite3_vfs*, void* handle, const char* symbol) {
      return RealVfs()->xDlSym(RealVfs(), handle, symbol);
    };
    g_vfs.xDlClose = [](sqlite3_vfs*, void* handle) { RealVfs()->xDlClose(RealVfs(), handle); };
    g_vfs.xRandomness = [](sqlite3_vfs*, int n, char* out) {
      return RealVfs()->xRandomness(RealVfs(), n, out);
    };
    g_vfs.xSleep = [](sqlite3_vfs*, int us) { return RealVfs()->xSleep(RealVfs(), us); };
    g_vfs.xCurrentTime = [](sqlite3_vfs*, double* out) {
      return RealVfs()->xCurrentTime(RealVfs(), out);
    };
    g_vfs.xGetLastError = [](sqlite3_vfs*, int n, char* out) {
      return RealVfs()->xGetLastError(RealVfs(), n, out);
    };
    g_vfs.xCurrentTimeInt64 = [](sqlite3_vfs*, sqlite3_int64* out) {
      return RealVfs()->xCurrentTimeInt64(RealVfs(), out);
    };
    sqlite3_vfs_register(&g_vfs, 0);
  });
  return kVfsName;
}

// What a sqlite3 file's header says of its size: `bytes` is 0 when the header does not say
// (the in-header page count is only valid when the change counter at byte 24 equals the
// version-valid-for number at byte 92).
struct HeaderSize {
  std::uint64_t page_size = 0;
  std::uint64_t bytes = 0;
};

HeaderSize ReadHeaderSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[100] = {};
  in.read(reinterpret_cast<char*>(h), sizeof(h));
  if (in.gcount() != sizeof(h)) return {};
  const auto be32 = [&](int at) {
    return std::uint32_t{h[at]} << 24 | std::uint32_t{h[at + 1]} << 16 |
           std::uint32_t{h[at + 2]} << 8 | std::uint32_t{h[at + 3]};
  };
  const std::uint32_t raw_page = std::uint32_t{h[16]} << 8 | h[17];
  HeaderSize size;
  size.page_size = raw_page == 1 ? 65536 : raw_page;
  if (be32(24) == be32(92)) size.bytes = size.page_size * be32(28);
  return size;
}

class Database {
 public:
  explicit Database(const std::string& path) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, NoShortReadVfs()) != SQLITE_OK) {
      // A failed open still allocates the handle, and a throwing constructor runs no destructor.
      const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : "cannot open";
      sqlite3_close(db_);
      db_ = nullptr;
      throw ParseError(path_ + ": sqlite3 open: " + message);
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
  /// sqlite3_step's code: SQLITE_ROW, SQLITE_DONE or an error.
  int TryStep() { return sqlite3_step(st_); }
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

namespace {

// custom_data from the YAML copy of metadata.yaml that rosbag2 keeps in the metadata table
// since schema version 3.
void ReadMetadataTable(const Database& db, const std::string& path, RawBag* bag) {
  bool has_metadata = false;
  {
    Statement table(db, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'metadata'");
    has_metadata = table.Step();
  }
  if (!has_metadata) return;
  Statement metadata(db, "SELECT metadata FROM metadata ORDER BY id DESC LIMIT 1");
  if (!metadata.Step()) return;
  try {
    const YamlNode root = YamlNode::LoadString(metadata.Text(0), path + ": metadata table");
    if (const auto info = root.Optional("rosbag2_bagfile_information")) {
      if (const auto custom = info->Optional("custom_data")) {
        for (const std::string& key : custom->Keys()) {
          bag->custom_data[key] = custom->Get<std::string>(key);
        }
      }
    }
  } catch (const ConfigError& e) {
    throw ParseError(e.what());
  }
}

}  // namespace

RawBag ReadSqliteBagFile(const std::string& path, bool recover_cut) {
  std::error_code ec;
  const std::uint64_t file_size = fs::file_size(path, ec);
  const HeaderSize header = ReadHeaderSize(path);
  const bool cut = !ec && (file_size < header.bytes ||
                           (header.page_size > 0 && file_size % header.page_size != 0));
  if (cut && !recover_cut) {
    throw ParseError(path + ": truncated: the sqlite3 header says " + std::to_string(header.bytes) +
                     " bytes, the file has " + std::to_string(file_size));
  }
  Database db(path);
  if (cut) {
    // sqlite3 refuses a file shorter than its header says unless the schema is writable (which
    // a read-only connection never uses to write); it then takes the pages the file has, and a
    // page past them is a "malformed" error.
    if (sqlite3_exec(db.get(), "PRAGMA writable_schema=ON;", nullptr, nullptr, nullptr) !=
        SQLITE_OK) {
      db.Fail("PRAGMA writable_schema");
    }
  }
  RawBag bag;
  std::map<std::int64_t, std::size_t> topic_index;
  {
    Statement topics(db, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
    while (topics.Step()) {
      topic_index[topics.Int(0)] = bag.topics.size();
      bag.topics.push_back({topics.Text(1), topics.Text(2), topics.Text(3)});
    }
  }
  if (!recover_cut) {
    ReadMetadataTable(db, path, &bag);
  } else {
    // rosbag2 writes the row when it closes the bag: a recording killed mid-way has none, and
    // a cut file may have lost its page.
    try {
      ReadMetadataTable(db, path, &bag);
    } catch (const ParseError&) {
      bag.custom_data.clear();
    }
  }
  Statement messages(db, "SELECT id, topic_id, timestamp, data FROM messages ORDER BY id");
  std::int64_t last_id = 0;
  while (true) {
    const int rc = messages.TryStep();
    if (rc == SQLITE_DONE) break;
    if (rc != SQLITE_ROW) {
      if (!recover_cut) db.Fail("read");
      // Rows are read in id order, so what was read is every message before the first row
      // sqlite3 cannot read.
      bag.cut = RawBagCut{cut ? "truncated at byte " + GroupedCount(file_size)
                              : "unreadable after message id " + std::to_string(last_id) +
                                    " (sqlite3: " + sqlite3_errmsg(db.get()) + ")",
                          false};
      break;
    }
    const auto it = topic_index.find(messages.Int(1));
    if (it == topic_index.end()) {
      throw ParseError(path + ": messages row " + std::to_string(messages.Int(0)) + ": topic_id " +
                       std::to_string(messages.Int(1)) + " is not in topics");
    }
    last_id = messages.Int(0);
    bag.messages.push_back({it->second, messages.Int(2), messages.Blob(3)});
  }
  if (cut && !bag.cut) bag.cut = RawBagCut{"truncated at byte " + GroupedCount(file_size), false};
  return bag;
}

}  // namespace slamrig::slam
