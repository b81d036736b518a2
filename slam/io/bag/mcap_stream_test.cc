// MCAP streams: McapWriter's stream form, BagSink writing one, McapStreamReader taking it in
// pieces of any size, its refusals, and the two messages a streaming program answers with.
#include "slam/io/bag/mcap_stream.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include "slam/io/bag/bag_sink.h"
#include "slam/io/bag/cdr.h"
#include "slam/io/bag/mcap_records.h"
#include "slam/io/bag/mcap_writer.h"
#include "slam/io/bag/raw_bag.h"
#include "slam/io/bag/ros_messages.h"
#include "slam/io/bag/testing/synthetic_records.h"
#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ParseError& e) {
    return e.what();
  }
  return "no error";
}

// Every message of `bytes`, fed in pieces of random sizes (1 byte up to `max_piece`).
std::vector<McapStreamMessage> ReadInPieces(const std::string& bytes, std::size_t max_piece,
                                            std::uint32_t seed, bool* ended) {
  McapStreamReader reader("test stream");
  std::mt19937 random(seed);
  std::vector<McapStreamMessage> messages;
  std::size_t at = 0;
  while (at < bytes.size()) {
    const std::size_t n = std::min(
        bytes.size() - at, std::uniform_int_distribution<std::size_t>(1, max_piece)(random));
    reader.Feed(std::string_view(bytes).substr(at, n));
    at += n;
    while (auto m = reader.Next()) messages.push_back(std::move(*m));
  }
  *ended = reader.ended();
  return messages;
}

// A small stream: two schemas, three channels, metadata, messages.
std::string SmallStream(int messages) {
  std::string bytes;
  McapWriter writer([&](std::string_view b) { bytes.append(b); }, McapWriterOptions{});
  writer.AddMetadata("slamrig.robot", {{"wheel_radius_m", "0.127"}});
  const std::uint16_t pose = writer.AddSchema("geometry_msgs/msg/PoseStamped", "ros2msg", "x");
  const std::uint16_t grid = writer.AddSchema("nav_msgs/msg/OccupancyGrid", "ros2msg", "y");
  const std::uint16_t a = writer.AddChannel(pose, "/estimate", "cdr", {});
  const std::uint16_t b = writer.AddChannel(grid, "/map", "cdr", {{"k", "v"}});
  const std::uint16_t c = writer.AddChannel(0, "/raw", "json", {});
  for (int i = 0; i < messages; ++i) {
    const std::uint16_t channel = i % 3 == 0 ? a : i % 3 == 1 ? b : c;
    writer.WriteMessage(channel, static_cast<std::uint32_t>(i), 1000u * i, 1000u * i,
                        std::string(static_cast<std::size_t>(i * 7 % 50), static_cast<char>(i)));
  }
  writer.Close();
  return bytes;
}

TEST(McapStreamTest, WhatTheWriterStreamsTheReaderTakesInPiecesOfAnySize) {
  const std::string bytes = SmallStream(40);
  for (std::size_t piece : {std::size_t{1}, std::size_t{3}, std::size_t{64}, bytes.size()}) {
    bool ended = false;
    const std::vector<McapStreamMessage> messages = ReadInPieces(bytes, piece, 7, &ended);
    EXPECT_TRUE(ended);
    ASSERT_EQ(messages.size(), 40u) << piece;
    for (int i = 0; i < 40; ++i) {
      const McapStreamMessage& m = messages[static_cast<std::size_t>(i)];
      EXPECT_EQ(m.topic, i % 3 == 0 ? "/estimate" : i % 3 == 1 ? "/map" : "/raw");
      EXPECT_EQ(m.schema, i % 3 == 0   ? "geometry_msgs/msg/PoseStamped"
                          : i % 3 == 1 ? "nav_msgs/msg/OccupancyGrid"
                                       : "");
      EXPECT_EQ(m.encoding, i % 3 == 2 ? "json" : "cdr");
      EXPECT_EQ(m.log_time_ns, 1000u * static_cast<std::uint64_t>(i));
      EXPECT_EQ(m.data, std::string(static_cast<std::size_t>(i * 7 % 50), static_cast<char>(i)));
    }
  }
}

TEST(McapStreamTest, AStreamIsAValidMcapFileWithItsCrcs) {
  slamrig::testing::TempDir dir;
  const std::string bytes = SmallStream(12);
  const std::string path = dir.path() / "stream.mcap";
  std::ofstream(path, std::ios::binary) << bytes;
  const RawBag bag = ReadMcapFile(path);  // checks the magic at both ends and the data CRC
  ASSERT_EQ(bag.messages.size(), 12u);
  EXPECT_EQ(bag.topics[bag.messages[4].topic].name, "/map");
  EXPECT_EQ(bag.messages[11].data, std::string(27, '\x0b'));
  // Record by record: no chunk, no index, no summary; each record where it was added.
  std::vector<int> ops;
  for (std::size_t at = 8; at + 9 <= bytes.size() - 8;) {
    std::uint64_t length;
    std::memcpy(&length, bytes.data() + at + 1, 8);
    ops.push_back(static_cast<std::uint8_t>(bytes[at]));
    at += 9 + length;
  }
  std::vector<int> expected = {mcap::kHeader,  mcap::kMetadata, mcap::kSchema, mcap::kSchema,
                               mcap::kChannel, mcap::kChannel,  mcap::kChannel};
  expected.insert(expected.end(), 12, mcap::kMessage);
  expected.push_back(mcap::kDataEnd);
  expected.push_back(mcap::kFooter);
  EXPECT_EQ(ops, expected);
}

// The stream form of BagSink carries exactly what its bag form writes to a file.
TEST(McapStreamTest, BagSinkStreamsTheMessagesOfItsBags) {
  slamrig::testing::TempDir dir;
  const Dataset data = testing::SyntheticRun(1.0, 3, 181);
  BagSinkOptions options;
  std::string bytes;
  BagSink stream([&](std::string_view b) { bytes.append(b); }, options);
  BagSink bag((dir.path() / "bag").string(), options);
  for (const Record& r : data.records) {
    stream.Add(r, nullptr);
    bag.Add(r, nullptr);
  }
  stream.Commit();
  bag.Commit();
  const RawBag file = ReadMcapFile((dir.path() / "bag/bag_0.mcap").string());
  bool ended = false;
  const std::vector<McapStreamMessage> messages = ReadInPieces(bytes, 5000, 1, &ended);
  EXPECT_TRUE(ended);
  ASSERT_EQ(messages.size(), file.messages.size());
  ASSERT_GT(messages.size(), 200u);
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const RawBagTopic& topic = file.topics[file.messages[i].topic];
    EXPECT_EQ(messages[i].topic, topic.name) << i;
    EXPECT_EQ(messages[i].schema, topic.type) << i;
    EXPECT_EQ(static_cast<std::int64_t>(messages[i].log_time_ns), file.messages[i].log_time_ns);
    EXPECT_EQ(messages[i].data, file.messages[i].data) << i;
  }
}

TEST(McapStreamTest, RefusesWhatIsNotAStreamNamingTheByte) {
  const auto read_all = [](const std::string& bytes) {
    McapStreamReader reader("its stdout", 1 << 20);
    reader.Feed(bytes);
    while (reader.Next()) {
    }
    return reader.ended();
  };
  EXPECT_THAT(ErrorOf([&] { read_all("no poses here\n"); }),
              HasSubstr("its stdout: byte 0: not an MCAP stream (it starts with 'no poses "
                        "here\\x0a')"));
  // A prefix of the magic is only waited on.
  EXPECT_FALSE(read_all(std::string(mcap::kMagic, 5)));
  const std::string good = SmallStream(3);
  const std::string magic(mcap::kMagic, sizeof(mcap::kMagic));
  std::string record;
  mcap::PutRecord(&record, mcap::kChunk, std::string(40, '\0'));
  EXPECT_THAT(ErrorOf([&] { read_all(magic + record); }),
              HasSubstr("byte 8: a Chunk record: a stream has its messages unchunked"));
  std::string huge;
  mcap::Put(&huge, static_cast<std::uint8_t>(mcap::kMessage));
  mcap::Put(&huge, std::uint64_t{1} << 40);
  EXPECT_THAT(ErrorOf([&] { read_all(magic + huge); }),
              HasSubstr("byte 8: record (opcode 5) of 1099511627776 bytes: longer than the "
                        "1048576 a record may have"));
  std::string orphan;
  mcap::PutRecord(&orphan, mcap::kMessage, std::string(22, '\0') + "x");
  EXPECT_THAT(ErrorOf([&] { read_all(magic + orphan); }),
              HasSubstr("message on channel 0, which no Channel record before it defines"));
  std::string short_message;
  mcap::PutRecord(&short_message, mcap::kMessage, "abc");
  EXPECT_THAT(ErrorOf([&] { read_all(magic + short_message); }),
              HasSubstr("Message record too short for its fields"));
  EXPECT_TRUE(read_all(good));
  EXPECT_THAT(ErrorOf([&] { read_all(good + "x"); }), HasSubstr("bytes after the closing magic"));
  std::string no_magic = good.substr(0, good.size() - 8) + "12345678";
  EXPECT_THAT(ErrorOf([&] { read_all(no_magic); }), HasSubstr("no closing magic after the Footer"));
}

TEST(McapStreamTest, PoseStampedAndOccupancyGridReadBackAsWritten) {
  std::string cdr;
  const Pose2 pose(1.25, -3.5, 2.75);
  EncodePoseStamped(Time{12'000'000'007}, "odom", pose, &cdr);
  const RosPoseStamped p = DecodePoseStamped(cdr);
  EXPECT_EQ(p.time, Time{12'000'000'007});
  EXPECT_EQ(p.frame_id, "odom");
  EXPECT_EQ(p.position.x(), 1.25);
  EXPECT_EQ(p.position.z(), 0.0);
  EXPECT_EQ(p.qz, std::sin(0.5 * 2.75));
  EXPECT_EQ(p.Planar().x(), 1.25);
  EXPECT_NEAR(p.Planar().theta(), 2.75, 1e-15);
  EXPECT_THROW(DecodePoseStamped(cdr.substr(0, cdr.size() - 1)), CdrError);

  RosOccupancyGrid grid;
  grid.time = Time{5};
  grid.frame_id = "map";
  grid.resolution_m = 0.1f;
  grid.width = 3;
  grid.height = 2;
  grid.origin = Pose2(-1.0, 2.0, 0.0);
  grid.data = {-1, 0, 100, 50, 0, -1};
  EncodeOccupancyGrid(grid, &cdr);
  const RosOccupancyGrid back = DecodeOccupancyGrid(cdr);
  EXPECT_EQ(back.frame_id, "map");
  EXPECT_EQ(back.resolution_m, 0.1f);
  EXPECT_EQ(back.width, 3u);
  EXPECT_EQ(back.height, 2u);
  EXPECT_EQ(back.origin, grid.origin);
  EXPECT_EQ(back.data, grid.data);
  // A cell count past the bytes there are is refused before anything is allocated.
  std::string cut = cdr.substr(0, cdr.size() - 6);
  EXPECT_THROW(DecodeOccupancyGrid(cut), CdrError);
}

}  // namespace
}  // namespace slamrig::slam
