// Bags cut short, as a recording killed mid-way leaves them: every cut at a seeded random byte
// reads the messages before the cut, identical to the same prefix of the whole bag, says where
// it stopped, and --strict (BagReaderOptions::strict) refuses it. Also the hints for a bag whose
// topics are not where the reader looks.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "slam/io/bag/bag_reader.h"
#include "slam/io/bag/bag_writer.h"
#include "slam/io/bag/mcap_records.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/io/bag/testing/synthetic_records.h"
#include "slam/io/log_reader.h"
#include "slam/types/error.h"
#include "tests/util/read_file.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;
using TempDir = slamrig::testing::TempDir;
using ::testing::HasSubstr;

void WriteAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// Writes a bag of `storage` and returns its one storage file.
std::string WriteTestBag(const TempDir& dir, BagStorage storage, McapCompression compression) {
  BagWriterOptions options;
  options.storage = storage;
  options.compression = compression;
  options.chunk_size_bytes = 4096;  // many chunks, so cuts fall between and inside them
  const std::string folder = dir.File("whole");
  WriteBag(testing::SyntheticRun(0.5, 7, 64), folder, options);
  return folder + "/whole_0" + (storage == BagStorage::kMcap ? ".mcap" : ".db3");
}

// A folder holding only `bytes` as its storage file: what a killed `ros2 bag record` leaves
// (metadata.yaml is written when the recording closes).
std::string CutBag(const TempDir& dir, const std::string& name, const std::string& bytes) {
  const std::string folder = dir.File("cut");
  fs::remove_all(folder);
  fs::create_directories(folder);
  WriteAll(folder + "/" + name, bytes);
  return folder;
}

std::size_t ScanCount(const RawBag& bag, std::size_t messages) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < messages; ++i) {
    n += bag.topics[bag.messages[i].topic].type == "sensor_msgs/msg/LaserScan";
  }
  return n;
}

// The first `n` messages of `cut` are those of `whole`, byte for byte.
void ExpectSameMessages(const RawBag& cut, const RawBag& whole, std::size_t n) {
  ASSERT_LE(n, whole.messages.size());
  for (std::size_t i = 0; i < n; ++i) {
    const RawBagMessage& a = cut.messages[i];
    const RawBagMessage& b = whole.messages[i];
    ASSERT_EQ(cut.topics[a.topic].name, whole.topics[b.topic].name) << i;
    ASSERT_EQ(a.log_time_ns, b.log_time_ns) << i;
    ASSERT_EQ(a.data, b.data) << i;
  }
}

bool SameRecord(const Record& a, const Record& b) {
  if (a.index() != b.index() || RecordTime(a) != RecordTime(b)) return false;
  if (const auto* s = std::get_if<LaserScan>(&a)) {
    const auto& t = std::get<LaserScan>(b);
    return s->ranges_m == t.ranges_m && s->angle_min_rad == t.angle_min_rad &&
           s->angle_increment_rad == t.angle_increment_rad && s->range_max_m == t.range_max_m &&
           s->base_from_laser == t.base_from_laser;
  }
  if (const auto* o = std::get_if<OdometryPose>(&a)) {
    return o->odom_from_base == std::get<OdometryPose>(b).odom_from_base;
  }
  if (const auto* w = std::get_if<WheelTicks>(&a)) {
    const auto& v = std::get<WheelTicks>(b);
    return w->right_ticks == v.right_ticks && w->left_ticks == v.left_ticks;
  }
  const auto& i = std::get<ImuSample>(a);
  const auto& j = std::get<ImuSample>(b);
  return i.angular_velocity_rad_s == j.angular_velocity_rad_s &&
         i.linear_acceleration_m_s2 == j.linear_acceleration_m_s2;
}

// `cut`'s records and reference are a prefix of `whole`'s.
void ExpectPrefix(const Dataset& cut, const Dataset& whole) {
  ASSERT_LE(cut.records.size(), whole.records.size());
  for (std::size_t i = 0; i < cut.records.size(); ++i) {
    ASSERT_TRUE(SameRecord(cut.records[i], whole.records[i])) << "record " << i;
  }
  ASSERT_LE(cut.reference.size(), whole.reference.size());
  for (std::size_t i = 0; i < cut.reference.size(); ++i) {
    ASSERT_EQ(cut.reference[i].time, whole.reference[i].time) << i;
    ASSERT_EQ(cut.reference[i].map_from_base, whole.reference[i].map_from_base) << i;
  }
}

std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const ParseError& e) {
    return e.what();
  }
  return "";
}

// Per top-level record of an MCAP file: where it ends, and how many messages are readable once
// the file reaches that far (every chunk's messages up to there, counted from the MessageIndex
// records that follow each chunk).
// `data_end` is set to the end of the DataEnd record: from there on, every message is known to
// be there.
std::vector<std::pair<std::size_t, std::size_t>> McapReadableAfter(const std::string& bytes,
                                                                   std::size_t* data_end) {
  const auto header = [&](std::size_t at, std::uint8_t* op, std::size_t* end) {
    std::uint64_t length;
    std::memcpy(&length, bytes.data() + at + 1, 8);
    *op = static_cast<std::uint8_t>(bytes[at]);
    *end = at + 9 + static_cast<std::size_t>(length);
  };
  std::vector<std::pair<std::size_t, std::size_t>> readable;
  std::size_t pos = sizeof(mcap::kMagic), total = 0;
  while (pos + 9 <= bytes.size()) {
    std::uint8_t op;
    std::size_t end;
    header(pos, &op, &end);
    if (op == mcap::kDataEnd) {
      *data_end = end;
      break;
    }
    if (op == mcap::kChunk) {
      std::uint8_t next_op;
      std::size_t next = end, next_end;
      while (next + 9 <= bytes.size() &&
             (header(next, &next_op, &next_end), next_op) == mcap::kMessageIndex) {
        std::uint32_t records;
        std::memcpy(&records, bytes.data() + next + 9 + 2, 4);
        total += records / 16;  // (log_time, offset) pairs
        next = next_end;
      }
    }
    readable.push_back({end, total});
    pos = end;
  }
  return readable;
}

class CutMcapTest : public ::testing::TestWithParam<McapCompression> {};

TEST_P(CutMcapTest, EveryCutReadsTheMessagesOfTheWholeChunksBeforeIt) {
  TempDir dir;
  const std::string file = WriteTestBag(dir, BagStorage::kMcap, GetParam());
  const std::string bytes = ReadFile(file);
  const RawBag whole = ReadMcapFile(file);
  const Dataset whole_data = ReadBag(CutBag(dir, "run_0.mcap", bytes));
  std::size_t data_end = 0;
  const auto readable = McapReadableAfter(bytes, &data_end);
  ASSERT_GT(data_end, readable.back().first);
  ASSERT_GT(readable.size(), 10u);
  ASSERT_EQ(readable.back().second, whole.messages.size());

  std::mt19937_64 rng(34);
  std::uniform_int_distribution<std::size_t> at(sizeof(mcap::kMagic), bytes.size() - 1);
  std::vector<std::size_t> cuts = {bytes.size() - 1, bytes.size() - 8};
  for (int i = 0; i < 25; ++i) cuts.push_back(at(rng));
  for (std::size_t i = 0; i < readable.size(); i += 3) {
    cuts.push_back(readable[i].first);  // exactly after a record
  }
  for (const std::size_t c : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(c) + " of " + std::to_string(bytes.size()));
    std::size_t expected = 0;
    for (const auto& [end, n] : readable) {
      if (end <= c) expected = n;
    }
    const std::string folder = CutBag(dir, "run_0.mcap", bytes.substr(0, c));
    const std::string cut_file = folder + "/run_0.mcap";
    const RawBag raw = ReadMcapFile(cut_file, true);
    ASSERT_TRUE(raw.cut.has_value());
    ASSERT_EQ(raw.messages.size(), expected);
    ExpectSameMessages(raw, whole, expected);
    EXPECT_THAT(ErrorOf([&] { ReadMcapFile(cut_file); }), HasSubstr("truncated"));
    BagReaderOptions strict;
    strict.strict = true;
    EXPECT_THAT(ErrorOf([&] { ReadBag(folder, strict); }),
                HasSubstr(cut_file + ": truncated: no Footer and closing magic at the end"));
    if (expected == 0) {
      EXPECT_EQ(ErrorOf([&] { ReadBag(folder); }),
                cut_file + ": truncated at byte " + GroupedCount(c) + ", before its first message");
      continue;
    }
    const Dataset data = ReadBag(folder);
    ExpectPrefix(data, whole_data);
    const std::string scans = GroupedCount(ScanCount(whole, expected)) + " scans";
    if (c >= data_end) {
      EXPECT_EQ(data.truncated, cut_file + " truncated at byte " + GroupedCount(c) +
                                    ", after its last message: all " + scans);
      EXPECT_EQ(data.records.size(), whole_data.records.size());
    } else {
      EXPECT_EQ(data.truncated, cut_file + " truncated at byte " + GroupedCount(c) +
                                    ": recovered " + scans +
                                    " of an unknown total; the rest is lost");
    }
    EXPECT_EQ(data.notes.front(), data.truncated);
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, CutMcapTest,
                         ::testing::Values(McapCompression::kZstd, McapCompression::kLz4,
                                           McapCompression::kNone));

TEST(CutMcapTest, DamageBeforeTheCutIsStillAnError) {
  TempDir dir;
  const std::string file = WriteTestBag(dir, BagStorage::kMcap, McapCompression::kNone);
  std::string bytes = ReadFile(file);
  bytes.resize(bytes.size() * 3 / 4);
  const std::size_t at = bytes.find(std::string("laser\0", 6));
  bytes[at] = static_cast<char>(bytes[at] ^ 0x10);
  const std::string folder = CutBag(dir, "run_0.mcap", bytes);
  EXPECT_THAT(ErrorOf([&] { ReadBag(folder); }), HasSubstr("chunk CRC mismatch"));
}

TEST(CutMcapTest, OnlyTheLastFileOfABagMayBeCut) {
  TempDir dir;
  const std::string file = WriteTestBag(dir, BagStorage::kMcap, McapCompression::kZstd);
  const std::string bytes = ReadFile(file);
  const std::string folder = dir.File("split");
  fs::create_directories(folder);
  WriteAll(folder + "/a_0.mcap", bytes.substr(0, bytes.size() / 2));
  WriteAll(folder + "/a_1.mcap", bytes);
  WriteAll(folder + "/metadata.yaml",
           "rosbag2_bagfile_information:\n  version: 6\n  storage_identifier: mcap\n"
           "  relative_file_paths:\n    - a_0.mcap\n    - a_1.mcap\n");
  EXPECT_THAT(ErrorOf([&] { ReadBag(folder); }),
              HasSubstr(folder + "/a_0.mcap: truncated at byte " + GroupedCount(bytes.size() / 2) +
                        ", and it is not the bag's last file"));
}

// sqlite3 reads a b-tree whose pages may lie anywhere in the file, so which rows a cut leaves
// readable is sqlite3's to say; what is read must be a prefix of the rows in id order, never a
// row made of zeros, and no less when the cut is later.
TEST(CutSqliteTest, EveryCutReadsAPrefixOfTheRows) {
  TempDir dir;
  const std::string file = WriteTestBag(dir, BagStorage::kSqlite3, McapCompression::kNone);
  const std::string bytes = ReadFile(file);
  const RawBag whole = ReadSqliteBagFile(file);
  const Dataset whole_data = ReadBag(CutBag(dir, "run_0.db3", bytes));
  const std::size_t page = 4096;
  ASSERT_EQ(bytes.size() % page, 0u);

  std::mt19937_64 rng(34);
  std::uniform_int_distribution<std::size_t> at(page, bytes.size() - 1);
  std::vector<std::size_t> cuts;
  for (int i = 0; i < 30; ++i) cuts.push_back(at(rng));
  for (int i = 0; i < 15; ++i) cuts.push_back(at(rng) / page * page);  // at a page boundary
  std::sort(cuts.begin(), cuts.end());
  std::size_t previous = 0, recovered_anything = 0;
  for (const std::size_t c : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(c) + " of " + std::to_string(bytes.size()));
    const std::string folder = CutBag(dir, "run_0.db3", bytes.substr(0, c));
    const std::string cut_file = folder + "/run_0.db3";
    EXPECT_THAT(
        ErrorOf([&] { ReadSqliteBagFile(cut_file); }),
        HasSubstr(cut_file + ": truncated: the sqlite3 header says " +
                  std::to_string(bytes.size()) + " bytes, the file has " + std::to_string(c)));
    RawBag raw;
    try {
      raw = ReadSqliteBagFile(cut_file, true);
    } catch (const ParseError& e) {
      // Only when the pages of the topics table are gone.
      EXPECT_THAT(e.what(), HasSubstr(cut_file)) << e.what();
      ASSERT_EQ(previous, 0u) << e.what();
      continue;
    }
    ASSERT_TRUE(raw.cut.has_value());
    EXPECT_EQ(raw.cut->where, "truncated at byte " + GroupedCount(c));
    ASSERT_GE(raw.messages.size(), previous);
    previous = raw.messages.size();
    ExpectSameMessages(raw, whole, raw.messages.size());
    if (raw.messages.empty()) continue;
    ++recovered_anything;
    const Dataset data = ReadBag(folder);
    ExpectPrefix(data, whole_data);
    EXPECT_EQ(data.truncated, cut_file + " truncated at byte " + GroupedCount(c) + ": recovered " +
                                  GroupedCount(ScanCount(whole, raw.messages.size())) +
                                  " scans of an unknown total; the rest is lost");
  }
  EXPECT_GT(recovered_anything, cuts.size() / 2);
}

// rosbag2's resilient preset records in WAL mode: committed transactions sit in the -wal file
// until a checkpoint, the one in progress when the recorder dies has no commit frame.
TEST(CutSqliteTest, AWalFileAddsItsCommittedTransactionsOnly) {
  TempDir dir;
  const std::string file = WriteTestBag(dir, BagStorage::kSqlite3, McapCompression::kNone);
  const RawBag whole = ReadSqliteBagFile(file);
  const std::string folder = dir.File("wal");
  fs::create_directories(folder);
  const std::string db_path = folder + "/run_0.db3";
  fs::copy_file(file, db_path);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db_path.c_str(), &db), SQLITE_OK);
  auto exec = [&](const std::string& sql) {
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
  };
  exec("PRAGMA journal_mode=WAL; PRAGMA wal_autocheckpoint=0; PRAGMA cache_size=1;");
  const std::string copy_rows =
      "INSERT INTO messages (topic_id, timestamp, data) SELECT topic_id, timestamp + 1000000000, "
      "data FROM messages WHERE id <= 30 ORDER BY id;";
  exec("BEGIN; " + copy_rows + " COMMIT;");
  // A transaction larger than the cache spills frames into the WAL before it commits.
  exec("BEGIN; " + copy_rows + copy_rows + copy_rows);
  // "Kill" the recorder: copy the files as they are now, with the transaction still open.
  const std::string crashed = dir.File("crashed");
  fs::create_directories(crashed);
  fs::copy_file(db_path, crashed + "/run_0.db3");
  fs::copy_file(db_path + "-wal", crashed + "/run_0.db3-wal");
  ASSERT_GT(fs::file_size(crashed + "/run_0.db3-wal"), 0u);
  exec("ROLLBACK;");
  sqlite3_close(db);

  const RawBag raw = ReadSqliteBagFile(crashed + "/run_0.db3", true);
  EXPECT_FALSE(raw.cut.has_value());
  ASSERT_EQ(raw.messages.size(), whole.messages.size() + 30);
  ExpectSameMessages(raw, whole, whole.messages.size());
  for (std::size_t i = 0; i < 30; ++i) {
    EXPECT_EQ(raw.messages[whole.messages.size() + i].log_time_ns,
              whole.messages[i].log_time_ns + 1'000'000'000);
  }
}

// Scans on another topic than /scan: the error lists what the bag has and the flag that maps it.
TEST(BagTopicHintTest, ScansOnAnotherTopicNameTheFlag) {
  TempDir dir;
  BagWriterOptions options;
  options.topics.scan = "/front/scan";
  options.clock_rate_hz = 0.0;
  const std::string folder = dir.File("b");
  WriteBag(testing::SyntheticRun(0.2, 2, 8), folder, options);
  EXPECT_EQ(ErrorOf([&] { ReadBag(folder); }),
            folder +
                ": no sensor_msgs/msg/LaserScan on /scan; the bag has /front/scan (LaserScan, 8), "
                "/ground_truth/odom (Odometry, 8), /imu (Imu, 20), /joint_states (JointState, 8), "
                "/odom (Odometry, 8), /tf (TFMessage, 8), /tf_static (TFMessage, 1): try --topic "
                "scan=/front/scan");
  LogReadOptions read;
  read.topics.scan = "/front/scan";
  const Dataset data = ReadLog(folder, read);
  EXPECT_EQ(std::count_if(data.records.begin(), data.records.end(),
                          [](const Record& r) { return std::holds_alternative<LaserScan>(r); }),
            8);
}

TEST(BagTopicHintTest, NothingReadListsEveryTopicAndEachFlag) {
  TempDir dir;
  BagWriterOptions options;
  options.topics.scan = "/front/scan";
  options.topics.odom = "/wheel/odom";
  options.topics.imu = "/imu/data";
  options.topics.joint_states = "/wheels";
  options.topics.ground_truth = "/truth";
  options.clock_rate_hz = 0.0;
  options.write_tf = false;
  const std::string folder = dir.File("b");
  WriteBag(testing::SyntheticRun(0.1, 2, 8), folder, options);
  EXPECT_EQ(ErrorOf([&] { ReadBag(folder); }),
            folder +
                ": no sensor_msgs/msg/LaserScan on /scan, no sensor_msgs/msg/JointState on "
                "/joint_states, no nav_msgs/msg/Odometry on /odom, no sensor_msgs/msg/Imu on "
                "/imu; the bag has /front/scan (LaserScan, 4), /imu/data (Imu, 10), /tf_static "
                "(TFMessage, 1), /truth (Odometry, 4), /wheel/odom (Odometry, 4), /wheels "
                "(JointState, 4): try --topic "
                "scan=/front/scan --topic joint_states=/wheels --topic odom=/wheel/odom --topic "
                "imu=/imu/data");
}

TEST(BagTopicHintTest, AnotherOdometryTopicBesideTheScansIsANote) {
  TempDir dir;
  BagWriterOptions options;
  options.topics.odom = "/wheel/odom";
  const std::string folder = dir.File("b");
  WriteBag(testing::SyntheticRun(0.2, 2, 8), folder, options);
  const Dataset data = ReadBag(folder);
  EXPECT_NE(std::find(data.notes.begin(), data.notes.end(),
                      "no nav_msgs/msg/Odometry on /odom (try --topic odom=/wheel/odom)"),
            data.notes.end());
}

TEST(BagTopicHintTest, AFileThatIsNoLogSaysWhatItIsNot) {
  TempDir dir;
  const std::string bin = dir.Write("x.bin", std::string("\x7f"
                                                         "ELF\x02\x01\x01\0\0\0",
                                                         10));
  EXPECT_EQ(ErrorOf([&] { ReadLog(bin); }),
            bin +
                ": not a log: no MCAP magic, no SQLite header, not gzip, not text (starts with "
                "7f 45 4c 46 02 01 01 00 ...)");
  const std::string mcap = dir.Write("y.mcap", "PK\x03\x04");
  EXPECT_EQ(ErrorOf([&] { ReadBag(mcap); }),
            mcap + ": byte 0: not a bag: no MCAP magic, no SQLite header");
}

}  // namespace
}  // namespace slamrig::slam
