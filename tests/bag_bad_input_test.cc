// Damaged ROS 2 bags through the slamrig binary (issue 12, item 5): a truncated .mcap or .db3
// (read strictly: by default a cut file is read up to the cut), a flipped byte inside an MCAP
// chunk, and a bag whose /scan topic has the wrong message type each end, in `slamrig slam` and in
// `slamrig run` (a scenario with `source: {log: BAG}`), in one error line naming the file, a
// non-zero exit code and no output folder.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;

std::string Binary() { return SLAMRIG_BINARY; }

// `slamrig simulate` of a short office run as a bag folder DIR/NAME/run.
std::string SimulateBag(const testing::TempDir& dir, const std::string& name,
                        const std::string& flags) {
  const std::string out = dir.File(name);
  const auto r = testing::RunCommand(Binary() + " simulate office --duration 4 --seed 2 " + flags +
                                     " --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return out + "/run";
}

// Flips one byte in the middle of the payload of the first Chunk record (opcode 0x06) of an
// MCAP file, walking the records from the 8-byte magic: opcode (1 byte), length (uint64 LE),
// content.
void FlipByteInFirstChunk(const std::string& path) {
  std::string bytes = ReadFile(path);
  std::size_t at = 8;
  while (at + 9 <= bytes.size()) {
    const auto opcode = static_cast<unsigned char>(bytes[at]);
    std::uint64_t length = 0;
    std::memcpy(&length, bytes.data() + at + 1, sizeof(length));  // little-endian host
    if (opcode == 0x06) {
      ASSERT_GT(length, 64u);
      // Past the chunk's fixed header (times, size, CRC, compression, records length).
      const std::size_t target = at + 9 + length / 2 + 16;
      bytes[target] = static_cast<char>(bytes[target] ^ 0x5a);
      std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
      return;
    }
    at += 9 + length;
  }
  FAIL() << path << ": no chunk";
}

// Expects `command` to fail with exactly one output line that contains `needle`.
void ExpectOneErrorLine(const std::string& command, const std::string& needle,
                        const std::string& out_dir) {
  const auto r = testing::RunCommand(command);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find("error"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(needle), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out_dir)) << r.output;
}

// Both commands on the bag at `bag`; `strict` refuses a cut file (else read up to the cut).
void ExpectRejected(const testing::TempDir& dir, const std::string& bag, const std::string& needle,
                    bool strict = false) {
  SCOPED_TRACE(bag);
  ExpectOneErrorLine(Binary() + " slam " + bag + " --algorithm dead-reckoning --quiet --out " +
                         dir.File("slam_out") + (strict ? " --strict" : ""),
                     needle, dir.File("slam_out"));
  const std::string scenario = dir.Write(
      "bad_bag.yaml", "name: bad_bag\nsource: {log: " + bag + (strict ? ", strict: true" : "") +
                          "}\nslam:\n  dr: {algorithm: dead-reckoning}\n");
  ExpectOneErrorLine(Binary() + " run " + scenario + " --quiet --out " + dir.File("run_out"),
                     needle, dir.File("run_out"));
}

TEST(BagBadInputTest, TruncatedMcap) {
  testing::TempDir dir;
  const std::string bag = SimulateBag(dir, "m", "--format mcap");
  const std::string file = bag + "/run_0.mcap";
  fs::resize_file(file, fs::file_size(file) * 2 / 3);
  ExpectRejected(dir, bag, file + ": truncated", true);
}

TEST(BagBadInputTest, TruncatedDb3) {
  testing::TempDir dir;
  const std::string bag = SimulateBag(dir, "s", "--format sqlite3");
  const std::string file = bag + "/run_0.db3";
  fs::resize_file(file, fs::file_size(file) * 2 / 3);
  ExpectRejected(dir, bag, file + ": truncated", true);
}

TEST(BagBadInputTest, FlippedByteInAChunk) {
  testing::TempDir dir;
  for (const char* compression : {"zstd", "none"}) {
    SCOPED_TRACE(compression);
    const std::string bag = SimulateBag(dir, std::string("f_") + compression,
                                        std::string("--format mcap --compression ") + compression);
    const std::string file = bag + "/run_0.mcap";
    FlipByteInFirstChunk(file);
    ExpectRejected(dir, bag, file);
  }
}

TEST(BagBadInputTest, WrongMessageType) {
  testing::TempDir dir;
  // IMU samples on /scan: the reader expects sensor_msgs/msg/LaserScan there.
  const std::string bag =
      SimulateBag(dir, "t", "--format mcap --topic imu=/scan --topic scan=/laser");
  ExpectRejected(dir, bag, "topic /scan: type 'sensor_msgs/msg/Imu', expected");
}

}  // namespace
}  // namespace slamrig
