#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "slam/io/bag/bag_reader.h"
#include "slam/io/bag/bag_writer.h"
#include "slam/io/bag/cdr.h"
#include "slam/io/bag/mcap_writer.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/io/bag/testing/synthetic_records.h"
#include "slam/types/error.h"
#include "tests/util/read_file.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;
using TempDir = slamrig::testing::TempDir;

void WriteAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

bool SameRecord(const Record& a, const Record& b) {
  if (a.index() != b.index()) return false;
  if (const auto* s = std::get_if<LaserScan>(&a)) {
    const auto& t = std::get<LaserScan>(b);
    return s->time == t.time && s->angle_min_rad == t.angle_min_rad &&
           s->angle_increment_rad == t.angle_increment_rad &&
           s->time_increment_s == t.time_increment_s && s->range_min_m == t.range_min_m &&
           s->range_max_m == t.range_max_m && s->ranges_m == t.ranges_m &&
           s->base_from_laser == t.base_from_laser;
  }
  if (const auto* o = std::get_if<OdometryPose>(&a)) {
    const auto& p = std::get<OdometryPose>(b);
    return o->time == p.time && o->odom_from_base == p.odom_from_base;
  }
  if (const auto* w = std::get_if<WheelTicks>(&a)) {
    const auto& v = std::get<WheelTicks>(b);
    return w->time == v.time && w->right_ticks == v.right_ticks && w->left_ticks == v.left_ticks;
  }
  const auto& i = std::get<ImuSample>(a);
  const auto& j = std::get<ImuSample>(b);
  return i.time == j.time && i.angular_velocity_rad_s == j.angular_velocity_rad_s &&
         i.linear_acceleration_m_s2 == j.linear_acceleration_m_s2;
}

void ExpectSameData(const Dataset& got, const Dataset& want) {
  ASSERT_EQ(got.records.size(), want.records.size());
  for (std::size_t i = 0; i < want.records.size(); ++i) {
    ASSERT_TRUE(SameRecord(got.records[i], want.records[i])) << "record " << i;
  }
  ASSERT_EQ(got.reference.size(), want.reference.size());
  for (std::size_t i = 0; i < want.reference.size(); ++i) {
    EXPECT_EQ(got.reference[i].time, want.reference[i].time);
    EXPECT_EQ(got.reference[i].map_from_base, want.reference[i].map_from_base);
  }
}

// The error ReadBag throws for `path`, or "" if it reads fine.
std::string ReadError(const std::string& path, bool strict = false) {
  try {
    BagReaderOptions options;
    options.strict = strict;
    ReadBag(path, options);
  } catch (const ParseError& e) {
    return e.what();
  }
  return "";
}

class BagRoundTripTest : public ::testing::TestWithParam<std::pair<BagStorage, McapCompression>> {};

TEST_P(BagRoundTripTest, ReadsBackIdenticalRecords) {
  TempDir dir;
  const Dataset data = testing::SyntheticRun(1.0, 11, 64);
  BagWriterOptions options;
  options.storage = GetParam().first;
  options.compression = GetParam().second;
  options.chunk_size_bytes = 4096;
  const std::string folder = dir.File("run");
  WriteBag(data, folder, options);
  const Dataset back = ReadBag(folder);
  ExpectSameData(back, data);
  EXPECT_EQ(back.reference_kind, "ground truth (/ground_truth/odom)");
  // /clock and /tf were written but are not read: they are listed with their counts.
  ASSERT_EQ(back.notes.size(), 2u);
  EXPECT_EQ(back.notes[0], "skipped topic /clock (rosgraph_msgs/msg/Clock): 100 messages");
  EXPECT_EQ(back.notes[1], "skipped topic /tf (tf2_msgs/msg/TFMessage): 40 messages");
  // The storage file alone reads the same.
  const std::string file =
      folder + (options.storage == BagStorage::kMcap ? "/run_0.mcap" : "/run_0.db3");
  ExpectSameData(ReadBag(file), data);
}

INSTANTIATE_TEST_SUITE_P(Storages, BagRoundTripTest,
                         ::testing::Values(std::pair{BagStorage::kMcap, McapCompression::kZstd},
                                           std::pair{BagStorage::kMcap, McapCompression::kLz4},
                                           std::pair{BagStorage::kMcap, McapCompression::kNone},
                                           std::pair{BagStorage::kSqlite3,
                                                     McapCompression::kNone}));

// The bag records its ticks per revolution, so a reader needs no robot file to recover the
// exact ticks: from metadata.yaml, or from the storage file alone (MCAP channel metadata, the
// sqlite3 metadata table).
TEST(BagTest, TicksRoundTripExactlyWithTheBagsTicksPerRevolution) {
  TempDir dir;
  Dataset data;
  for (int i = 0; i < 500; ++i) {
    data.records.push_back(WheelTicks{Time{i * 1000}, {2'000'000, -7}, {1'999'999, 3}});
  }
  for (BagStorage storage : {BagStorage::kMcap, BagStorage::kSqlite3}) {
    BagWriterOptions options;
    options.storage = storage;
    options.ticks_per_revolution = 2578;
    const std::string folder = dir.File(std::string(BagStorageName(storage)));
    WriteBag(data, folder, options);
    ExpectSameData(ReadBag(folder), data);
    const std::string file = folder + "/" + std::string(BagStorageName(storage)) +
                             (storage == BagStorage::kMcap ? "_0.mcap" : "_0.db3");
    ExpectSameData(ReadBag(file), data);
    // Told otherwise, the reader believes the caller: other ticks come out.
    BagReaderOptions read_options;
    read_options.ticks_per_revolution = 360;
    const Dataset wrong = ReadBag(file, read_options);
    EXPECT_NE(std::get<WheelTicks>(wrong.records[0]).right_ticks[0], 2'000'000);
  }
}

TEST(BagTest, OtherTopicNamesAndUnknownTopics) {
  TempDir dir;
  const Dataset data = testing::SyntheticRun(0.2, 2, 8);
  BagWriterOptions options;
  options.topics.scan = "/base_scan";
  WriteBag(data, dir.File("b"), options);
  // With the default names, the scans on /base_scan are not read: the error names the flag.
  EXPECT_THAT(ReadError(dir.File("b")),
              ::testing::HasSubstr("no sensor_msgs/msg/LaserScan on /scan; the bag has "
                                   "/base_scan (LaserScan, 8), /clock (Clock, 20), "));
  EXPECT_THAT(ReadError(dir.File("b")), ::testing::EndsWith(": try --topic scan=/base_scan"));
  BagReaderOptions read_options;
  read_options.topics.scan = "/base_scan";
  ExpectSameData(ReadBag(dir.File("b"), read_options), data);
}

TEST(BagTest, EmptyBagsAreValid) {
  TempDir dir;
  for (BagStorage storage : {BagStorage::kMcap, BagStorage::kSqlite3}) {
    BagWriterOptions options;
    options.storage = storage;
    const std::string folder = dir.File(std::string(BagStorageName(storage)));
    WriteBag(Dataset{}, folder, options);
    const Dataset back = ReadBag(folder);
    EXPECT_TRUE(back.records.empty());
    EXPECT_TRUE(back.reference.empty());
    EXPECT_NE(ReadFile(folder + "/metadata.yaml").find("  message_count: 0\n"), std::string::npos);
  }
}

TEST(BagTest, UncommittedWriterLeavesNothing) {
  TempDir dir;
  {
    BagWriter writer(dir.File("bag"), {});
    writer.Write(Record{OdometryPose{Time{1}, Pose2()}});
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
  fs::create_directories(dir.File("exists"));
  EXPECT_THROW(BagWriter(dir.File("exists"), {}), std::runtime_error);
  BagWriterOptions bad;
  bad.topics.imu = "imu";
  EXPECT_THROW(BagWriter(dir.File("x"), bad), ConfigError);
  McapWriterOptions tiny_chunks;
  tiny_chunks.chunk_size_bytes = 10;
  try {
    McapWriter(dir.File("x.mcap"), tiny_chunks);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "mcap writer: chunk_size_bytes = 10; must be >= 1024");
  }
  EXPECT_FALSE(fs::exists(dir.File("x.mcap")));
}

TEST(BagTest, MetadataListsTopicsAndCounts) {
  TempDir dir;
  // 0.1 s: 10 IMU samples and 4 each of ticks, odometry, scans and truth; 4 /tf, 1 /tf_static
  // and 10 /clock (100 Hz) messages: 41 in all.
  WriteBag(testing::SyntheticRun(0.1, 1, 8), dir.File("m"), {});
  const std::string yaml = ReadFile(dir.File("m/metadata.yaml"));
  for (const char* key :
       {"rosbag2_bagfile_information:\n  version: 6\n  storage_identifier: mcap\n",
        "  custom_data:\n    slamrig.ticks_per_revolution: \"360\"\n", "  message_count: 41\n",
        "        name: /scan\n        type: sensor_msgs/msg/LaserScan\n",
        "  relative_file_paths:\n    - m_0.mcap\n"}) {
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
  }
}

TEST(BagTest, AnRgbdFrameIsTwoImagesAndACameraInfo) {
  TempDir dir;
  RgbdFrame frame;
  frame.time = Time{1'500'000'000};
  frame.width = 2;
  frame.height = 2;
  frame.rgb = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  frame.depth_m = {0.5f, 1.25f, 0.0f, 4.0f};
  frame.intrinsics = {100.0, 100.0, 0.5, 0.5};
  {
    BagWriterOptions options;
    options.compression = McapCompression::kNone;
    BagWriter writer(dir.File("f"), options);
    writer.Write(Record{frame});
    writer.Commit();
  }
  const RawBag bag = ReadMcapFile(dir.File("f/f_0.mcap"));
  std::map<std::string, std::string> type_of, data_of;
  for (const RawBagTopic& t : bag.topics) type_of[t.name] = t.type;
  for (const RawBagMessage& m : bag.messages) {
    EXPECT_EQ(m.log_time_ns, frame.time.ns);
    data_of[bag.topics[m.topic].name] = m.data;
  }
  const BagTopicNames names;
  EXPECT_EQ(type_of[names.rgb], "sensor_msgs/msg/Image");
  EXPECT_EQ(type_of[names.depth], "sensor_msgs/msg/Image");
  EXPECT_EQ(type_of[names.camera_info], "sensor_msgs/msg/CameraInfo");

  // sensor_msgs/Image: header, height, width, encoding, is_bigendian, step, data.
  const auto image = [](const std::string& bytes, const char* encoding) {
    CdrReader r(bytes);
    EXPECT_EQ(r.Int32(), 1);
    EXPECT_EQ(r.Uint32(), 500'000'000u);
    r.String();  // frame_id
    EXPECT_EQ(r.Uint32(), 2u);
    EXPECT_EQ(r.Uint32(), 2u);
    EXPECT_EQ(r.String(), encoding);
    // Then is_bigendian (one byte, 0), step aligned to 4 and the data sequence: checked below.
  };
  image(data_of[names.rgb], "rgb8");
  image(data_of[names.depth], "32FC1");
  const std::string& rgb = data_of[names.rgb];
  EXPECT_EQ(rgb.substr(rgb.size() - 12),
            std::string(reinterpret_cast<const char*>(frame.rgb.data()), 12));
  const std::string& depth = data_of[names.depth];
  EXPECT_EQ(depth.substr(depth.size() - 16),
            std::string(reinterpret_cast<const char*>(frame.depth_m.data()), 16));
  // The step and the data's length right before the data.
  std::uint32_t step = 0, count = 0;
  std::memcpy(&step, rgb.data() + rgb.size() - 12 - 8, 4);
  std::memcpy(&count, rgb.data() + rgb.size() - 12 - 4, 4);
  EXPECT_EQ(step, 6u);
  EXPECT_EQ(count, 12u);

  // sensor_msgs/CameraInfo: K from the intrinsics, no distortion.
  CdrReader info(data_of[names.camera_info]);
  info.Int32();
  info.Uint32();
  info.String();
  EXPECT_EQ(info.Uint32(), 2u);
  EXPECT_EQ(info.Uint32(), 2u);
  EXPECT_EQ(info.String(), "plumb_bob");
  EXPECT_EQ(info.Float64Sequence(), std::vector<double>(5, 0.0));
  EXPECT_EQ(info.Float64Array(9),
            (std::vector<double>{100.0, 0.0, 0.5, 0.0, 100.0, 0.5, 0.0, 0.0, 1.0}));

  // slamrig's reader has no use for the images: it reads the bag and says what it skipped.
  const Dataset back = ReadBag(dir.File("f"));
  EXPECT_TRUE(back.records.empty());
}

// --- hostile input --------------------------------------------------------------------------

class CorruptMcapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    BagWriterOptions options;
    options.compression = McapCompression::kNone;
    options.chunk_size_bytes = 4096;
    WriteBag(testing::SyntheticRun(0.5, 5, 64), dir_.File("b"), options);
    file_ = dir_.File("b/b_0.mcap");
    bytes_ = ReadFile(file_);
  }
  std::string ErrorAfter(const std::string& bytes, bool strict = false) {
    WriteAll(file_, bytes);
    return ReadError(dir_.File("b"), strict);
  }

  TempDir dir_;
  std::string file_;
  std::string bytes_;
};

// Read strictly; bag_cut_test.cc reads cut files up to the cut.
TEST_F(CorruptMcapTest, Truncated) {
  for (std::size_t n : {std::size_t{0}, std::size_t{5}, bytes_.size() / 2, bytes_.size() - 1}) {
    const std::string e = ErrorAfter(bytes_.substr(0, n), true);
    EXPECT_NE(e.find(file_), std::string::npos) << e;
    EXPECT_TRUE(e.find("truncated") != std::string::npos ||
                e.find("no MCAP magic") != std::string::npos)
        << e;
  }
}

TEST_F(CorruptMcapTest, BadMagic) {
  std::string b = bytes_;
  b[1] = 'X';
  EXPECT_EQ(ErrorAfter(b), file_ + ": byte 0: not a bag: no MCAP magic, no SQLite header");
  EXPECT_THROW(ReadMcapFile(file_), ParseError);
}

TEST_F(CorruptMcapTest, ChunkCrc) {
  std::string b = bytes_;
  // The first "laser" frame id is in a message inside the first (uncompressed) chunk.
  const std::size_t at = b.find(std::string("laser\0", 6));
  b[at] = static_cast<char>(b[at] ^ 0x10);
  const std::string e = ErrorAfter(b);
  EXPECT_NE(e.find("chunk CRC mismatch"), std::string::npos) << e;
}

TEST_F(CorruptMcapTest, DataSectionCrc) {
  std::string b = bytes_;
  const std::size_t at = b.find("float32 angle_min");  // the schema text, outside any chunk
  b[at] = 'F';
  const std::string e = ErrorAfter(b);
  EXPECT_NE(e.find("data section CRC mismatch"), std::string::npos) << e;
}

TEST_F(CorruptMcapTest, SummaryCrc) {
  std::string b = bytes_;
  const std::size_t at = b.rfind("/joint_states");  // the channel record in the summary
  b[at + 1] = 'J';
  const std::string e = ErrorAfter(b);
  EXPECT_NE(e.find("summary CRC mismatch"), std::string::npos) << e;
}

TEST_F(CorruptMcapTest, RecordLengthPastTheEnd) {
  std::string b = bytes_;
  b[8 + 1 + 6] = '\x7f';  // the Header record's length
  const std::string e = ErrorAfter(b);
  EXPECT_NE(e.find("runs past the end"), std::string::npos) << e;
}

TEST(CorruptBagTest, ChunkThatDoesNotDecompress) {
  for (McapCompression c : {McapCompression::kZstd, McapCompression::kLz4}) {
    TempDir dir;
    BagWriterOptions options;
    options.compression = c;
    WriteBag(testing::SyntheticRun(0.2, 5, 64), dir.File("b"), options);
    const std::string file = dir.File("b/b_0.mcap");
    std::string b = ReadFile(file);
    // Overwrite the start of the compressed records, just after the compression name.
    const std::string name(McapCompressionName(c));
    const std::string field = std::string(1, static_cast<char>(name.size())) +
                              std::string(3, '\0') + name;  // the Chunk's compression field
    const std::size_t at = b.find(field) + field.size() + 8 + 16;
    for (std::size_t i = 0; i < 32; ++i) b[at + i] = '\xff';
    WriteAll(file, b);
    const std::string e = ReadError(file);
    EXPECT_NE(e.find(file + ": byte "), std::string::npos) << e;
    EXPECT_NE(e.find(name + " chunk does not decompress"), std::string::npos) << e;
  }
}

TEST(CorruptBagTest, MessageThatDoesNotDecode) {
  TempDir dir;
  const std::string file = dir.File("bad.mcap");
  {
    McapWriter writer(file, {});
    const auto schema = writer.AddSchema("sensor_msgs/msg/LaserScan", "ros2msg",
                                         RosMessageDefinition(RosType::kLaserScan));
    const auto channel = writer.AddChannel(schema, "/scan", "cdr", {});
    LaserScan scan;
    scan.ranges_m = {1.0f, 2.0f, 3.0f};
    std::string good;
    EncodeLaserScan(scan, "laser", &good);
    writer.WriteMessage(channel, 0, 10, 10, good);
    writer.WriteMessage(channel, 1, 20, 20, good.substr(0, good.size() - 5));  // too short
    writer.Close();
  }
  const std::string e = ReadError(file);
  EXPECT_TRUE(
      e.starts_with(file + ": topic /scan: message 1: sequence at byte 56 claims 3 elements"))
      << e;
}

TEST(CorruptBagTest, WrongTypeForAReadTopic) {
  TempDir dir;
  const std::string file = dir.File("type.mcap");
  {
    McapWriter writer(file, {});
    const auto schema = writer.AddSchema("sensor_msgs/msg/Imu", "ros2msg", "");
    writer.AddChannel(schema, "/scan", "cdr", {});
    writer.Close();
  }
  EXPECT_EQ(ReadError(file),
            file + ": topic /scan: type 'sensor_msgs/msg/Imu', expected sensor_msgs/msg/LaserScan");
}

TEST(CorruptBagTest, SqliteBadMessageAndBadFile) {
  TempDir dir;
  BagWriterOptions options;
  options.storage = BagStorage::kSqlite3;
  WriteBag(testing::SyntheticRun(0.2, 5, 16), dir.File("s"), options);
  const std::string file = dir.File("s/s_0.db3");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  // The third /joint_states message gets a length field far past its end.
  ASSERT_EQ(sqlite3_exec(db,
                         "UPDATE messages SET data = substr(data, 1, 20) || X'FFFFFF7F' || "
                         "substr(data, 25) WHERE id = (SELECT m.id FROM messages m JOIN topics t "
                         "ON m.topic_id = t.id WHERE t.name = '/joint_states' ORDER BY m.id "
                         "LIMIT 1 OFFSET 2)",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  const std::string e = ReadError(dir.File("s"));
  EXPECT_TRUE(e.starts_with(file + ": topic /joint_states: message 2: sequence at byte")) << e;

  const std::string garbage = dir.Write("g.db3", std::string("SQLite format 3\0", 16) + "junk");
  EXPECT_TRUE(ReadError(garbage).starts_with(garbage + ": sqlite3")) << ReadError(garbage);
  const std::string text = dir.Write("t.mcap", "hello");
  EXPECT_EQ(ReadError(text), text + ": byte 0: not a bag: no MCAP magic, no SQLite header");
}

TEST(CorruptBagTest, BadMetadata) {
  TempDir dir;
  WriteBag(testing::SyntheticRun(0.1, 5, 8), dir.File("m"), {});
  const std::string yaml = dir.File("m/metadata.yaml");
  WriteAll(yaml, "rosbag2_bagfile_information:\n  storage_identifier: tape\n");
  std::string e = ReadError(dir.File("m"));
  EXPECT_NE(e.find("metadata.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("storage_identifier: 'tape' is not mcap or sqlite3"), std::string::npos) << e;
  WriteAll(yaml,
           "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n"
           "  relative_file_paths:\n    - m_0.mcap\n");
  e = ReadError(dir.File("m"));
  EXPECT_NE(e.find("metadata.yaml says storage 'sqlite3' but the file is MCAP"), std::string::npos)
      << e;
}

// Random damage (flipped bytes, overwritten runs, cuts) to a small bag of each kind: every read
// either succeeds or ends in one ParseError; nothing crashes or throws anything else.
TEST(CorruptBagTest, RandomDamageIsAParseErrorOrHarmless) {
  TempDir dir;
  std::mt19937_64 rng(17);
  for (const auto& [storage, compression] :
       {std::pair{BagStorage::kMcap, McapCompression::kZstd},
        std::pair{BagStorage::kMcap, McapCompression::kLz4},
        std::pair{BagStorage::kMcap, McapCompression::kNone},
        std::pair{BagStorage::kSqlite3, McapCompression::kNone}}) {
    BagWriterOptions options;
    options.storage = storage;
    options.compression = compression;
    options.chunk_size_bytes = 2048;
    const std::string folder = dir.File(std::string(BagStorageName(storage)) + "_" +
                                        std::string(McapCompressionName(compression)));
    WriteBag(testing::SyntheticRun(0.1, 9, 32), folder, options);
    const std::string file = folder + "/" + fs::path(folder).filename().string() +
                             (storage == BagStorage::kMcap ? "_0.mcap" : "_0.db3");
    const std::string good = ReadFile(file);
    int errors = 0;
    const int trials = 45;
    for (int trial = 0; trial < trials; ++trial) {
      std::string b = good;
      std::uniform_int_distribution<std::size_t> at(0, b.size() - 1);
      switch (trial % 3) {
        case 0:
          b[at(rng)] ^= static_cast<char>(1 << (rng() % 8));
          break;
        case 1:
          for (std::size_t i = at(rng), n = 0; i < b.size() && n < 16; ++i, ++n) {
            b[i] = static_cast<char>(rng());
          }
          break;
        default:
          b.resize(at(rng));
      }
      WriteAll(file, b);
      // Read up to a cut, then strictly (a cut is an error).
      try {
        ReadBag(folder);
      } catch (const ParseError& e) {
        EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      }
      try {
        BagReaderOptions strict;
        strict.strict = true;
        ReadBag(folder, strict);
      } catch (const ParseError& e) {
        ++errors;
        EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      }
    }
    // Most damage to MCAP hits a CRC; sqlite3 has none, so a damaged value often reads fine.
    EXPECT_GT(errors, storage == BagStorage::kMcap ? trials / 2 : trials / 10) << file;
    std::printf("%s: %d of %d damaged copies rejected\n", file.c_str(), errors, trials);
  }
}

}  // namespace
}  // namespace slamrig::slam
