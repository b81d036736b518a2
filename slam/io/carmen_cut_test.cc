// CARMEN logs cut short, plain and gzip: every cut at a seeded random byte reads the messages of
// the whole lines before it, identical to the same prefix of the whole log, and says where it
// stopped; `strict` keeps the errors. Also what ReadLog makes of a folder that holds runs.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "slam/io/carmen_reader.h"
#include "slam/io/carmen_writer.h"
#include "slam/io/dataset.h"
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

std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const ParseError& e) {
    return e.what();
  }
  return "";
}

// (sx * u, sy * u, st * u) from three draws of u, the last drawn first: sequenced (the arguments
// of one call are drawn in the compiler's order), in the order the logs here were generated with.
Pose2 RandomPose(std::mt19937_64& rng, std::uniform_real_distribution<double>& u, double sx,
                 double sy, double st) {
  const double theta = st * u(rng), y = sy * u(rng);
  return Pose2(sx * u(rng), y, theta);
}

// A log as `slamrig simulate` writes it: PARAMs, then ODOM, ROBOTLASER1 and TRUEPOS lines with
// random values, stamps from 1000 s.
std::string WriteTestLog(const TempDir& dir, int scans) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::string path = dir.File("whole.log");
  CarmenWriter writer(path);
  writer.WriteParam("laser_time_increment_s", "0.0001");
  writer.WriteParam("laser_range_min_m", "0.05");
  Pose2 odom;
  for (int k = 0; k < scans; ++k) {
    const Time t = Time::FromSeconds(1000.0 + 0.025 * k);
    odom = odom * RandomPose(rng, u, 0.01, 0.002, 0.01);
    const double turn = u(rng);  // drawn first, as in RandomPose
    writer.WriteOdometry(OdometryPose{t, odom}, u(rng), turn);
    LaserScan scan;
    scan.time = AddSeconds(t, 0.001);
    scan.angle_min_rad = -1.5;
    scan.angle_increment_rad = 0.05;
    scan.range_max_m = 30.0;
    for (int i = 0; i < 61; ++i) scan.ranges_m.push_back(static_cast<float>(5.0 + 4.0 * u(rng)));
    writer.WriteLaser(scan, odom);
    writer.WriteTruePos(GroundTruthPose{scan.time, RandomPose(rng, u, 1.0, 1.0, 1.0)}, odom);
  }
  writer.Commit();
  return path;
}

// The whole log's messages on lines up to `last_line`, against the cut log's.
void ExpectPrefix(const CarmenLog& cut, const CarmenLog& whole, int last_line) {
  std::size_t scans = 0, odometry = 0;
  while (scans < whole.scans.size() && whole.scans[scans].line <= last_line) ++scans;
  while (odometry < whole.odometry.size() && whole.odometry[odometry].line <= last_line) {
    ++odometry;
  }
  ASSERT_EQ(cut.scans.size(), scans);
  ASSERT_EQ(cut.odometry.size(), odometry);
  for (std::size_t i = 0; i < scans; ++i) {
    const CarmenScan& a = cut.scans[i];
    const CarmenScan& b = whole.scans[i];
    ASSERT_EQ(a.line, b.line);
    ASSERT_EQ(a.scan.time, b.scan.time);
    ASSERT_EQ(a.scan.ranges_m, b.scan.ranges_m);
    ASSERT_EQ(a.scan.angle_min_rad, b.scan.angle_min_rad);
    ASSERT_EQ(a.scan.angle_increment_rad, b.scan.angle_increment_rad);
    ASSERT_EQ(a.scan.time_increment_s, b.scan.time_increment_s);
    ASSERT_EQ(a.scan.range_min_m, b.scan.range_min_m);
    ASSERT_EQ(a.scan.range_max_m, b.scan.range_max_m);
    ASSERT_EQ(a.scan.base_from_laser, b.scan.base_from_laser);
    ASSERT_EQ(a.logged_pose, b.logged_pose);
  }
  for (std::size_t i = 0; i < odometry; ++i) {
    ASSERT_EQ(cut.odometry[i].odometry.time, whole.odometry[i].odometry.time);
    ASSERT_EQ(cut.odometry[i].odometry.odom_from_base, whole.odometry[i].odometry.odom_from_base);
  }
  ASSERT_LE(cut.true_poses.size(), whole.true_poses.size());
  for (std::size_t i = 0; i < cut.true_poses.size(); ++i) {
    ASSERT_EQ(cut.true_poses[i].time, whole.true_poses[i].time);
    ASSERT_EQ(cut.true_poses[i].map_from_base, whole.true_poses[i].map_from_base);
  }
}

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> tokens;
  std::istringstream in(text);
  for (std::string t; in >> t;) tokens.push_back(t);
  return tokens;
}

TEST(CarmenCutTest, EveryCutOfAPlainLogReadsItsWholeLines) {
  TempDir dir;
  const std::string text = ReadFile(WriteTestLog(dir, 60));
  const CarmenLog whole = ReadCarmenLog(dir.File("whole.log"));
  std::mt19937_64 rng(34);
  std::uniform_int_distribution<std::size_t> at(1, text.size() - 1);
  std::vector<std::size_t> cuts;
  for (int i = 0; i < 120; ++i) cuts.push_back(at(rng));
  // Inside the logger stamp that ends a line, and right after it.
  const std::size_t line_end = text.find('\n', text.size() / 2);
  cuts.push_back(line_end - 1);
  cuts.push_back(line_end);
  cuts.push_back(line_end + 1);
  const std::string path = dir.File("cut.log");
  for (const std::size_t c : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(c) + " of " + std::to_string(text.size()));
    const std::string prefix = text.substr(0, c);
    WriteAll(path, prefix);
    const int whole_lines = static_cast<int>(std::count(prefix.begin(), prefix.end(), '\n'));
    const std::string partial = prefix.substr(prefix.rfind('\n') + 1);
    // The partial line is a whole message when only its unread logger stamp is cut.
    const std::size_t next = text.find('\n', c);
    const std::string full_line = text.substr(c - partial.size(), next - (c - partial.size()));
    const bool kept = !partial.empty() && partial.back() != ' ' &&
                      Split(partial).size() == Split(full_line).size() &&
                      !partial.starts_with("PARAM");
    const int last_line = whole_lines + (kept ? 1 : 0);
    if (last_line < 3) {  // the two comment lines and a PARAM: no message yet
      EXPECT_THAT(ErrorOf([&] { ReadCarmenLog(path); }), HasSubstr("no CARMEN messages"));
      continue;
    }
    const CarmenLog log = ReadCarmenLog(path);
    ExpectPrefix(log, whole, last_line);
    if (partial.empty() || kept) {
      EXPECT_EQ(log.truncated, "");
    } else {
      EXPECT_EQ(log.truncated, path + " truncated in line " + std::to_string(whole_lines + 1) +
                                   ": recovered " + GroupedCount(log.scans.size()) +
                                   " scans of an unknown total; the rest is lost");
      EXPECT_EQ(log.notes.back(), log.truncated);
      const Dataset data = CarmenToDataset(log);
      EXPECT_EQ(data.truncated, log.truncated);
      // Strictly, the cut line is what it is: a malformed line, or one of an unknown type (cut
      // in its type) that adds nothing.
      try {
        const CarmenLog strict = ReadCarmenLog(path, {.strict = true});
        EXPECT_EQ(strict.scans.size(), log.scans.size());
        EXPECT_EQ(strict.odometry.size(), log.odometry.size());
        EXPECT_EQ(strict.stats.unknown_messages.count(Split(partial).front()), 1u);
      } catch (const ParseError& e) {
        EXPECT_THAT(e.what(), HasSubstr(path + ":" + std::to_string(whole_lines + 1) + ": "));
      }
    }
  }
}

std::string Gzip(const std::string& text, const std::string& path) {
  gzFile f = gzopen(path.c_str(), "wb");
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  return ReadFile(path);
}

// What zlib itself gets out of a cut gzip stream, independently of gzgets.
std::string Inflate(const std::string& compressed) {
  z_stream z{};
  inflateInit2(&z, 15 + 16);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  z.avail_in = static_cast<uInt>(compressed.size());
  std::string out;
  char buffer[65536];
  while (true) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof(buffer);
    const int rc = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof(buffer) - z.avail_out);
    if (rc != Z_OK) break;
  }
  inflateEnd(&z);
  return out;
}

TEST(CarmenCutTest, EveryCutOfAGzipLogReadsWhatDecompresses) {
  TempDir dir;
  const std::string text = ReadFile(WriteTestLog(dir, 200));
  const CarmenLog whole = ReadCarmenLog(dir.File("whole.log"));
  const std::string gz = Gzip(text, dir.File("whole.log.gz"));
  std::mt19937_64 rng(34);
  std::uniform_int_distribution<std::size_t> at(20, gz.size() - 1);
  std::vector<std::size_t> cuts = {gz.size() - 1, gz.size() - 8};  // in the trailer
  for (int i = 0; i < 40; ++i) cuts.push_back(at(rng));
  const std::string path = dir.File("cut.log.gz");
  for (const std::size_t c : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(c) + " of " + std::to_string(gz.size()));
    WriteAll(path, gz.substr(0, c));
    const std::string out = Inflate(gz.substr(0, c));
    ASSERT_TRUE(text.starts_with(out));
    const int whole_lines = static_cast<int>(std::count(out.begin(), out.end(), '\n'));
    EXPECT_THAT(ErrorOf([&] { ReadCarmenLog(path, {.strict = true}); }),
                HasSubstr("corrupt or truncated compressed data"));
    if (whole_lines < 3) {  // the two comment lines: no message yet
      EXPECT_THAT(ErrorOf([&] { ReadCarmenLog(path); }), HasSubstr("no CARMEN messages"));
      continue;
    }
    const CarmenLog log = ReadCarmenLog(path);
    ExpectPrefix(log, whole, whole_lines);
    const std::string recovered = ": recovered " + GroupedCount(log.scans.size()) +
                                  " scans of an unknown total; the rest "
                                  "is lost";
    if (out.ends_with('\n')) {
      EXPECT_EQ(log.truncated, path + ": compressed data cut short after line " +
                                   GroupedCount(whole_lines) + recovered);
    } else {
      EXPECT_EQ(log.truncated,
                path + " truncated in line " + GroupedCount(whole_lines + 1) + recovered);
    }
  }
}

TEST(CarmenCutTest, AWholeLastLineWithoutNewlineIsKept) {
  TempDir dir;
  const std::string text = ReadFile(WriteTestLog(dir, 5));
  const std::string path = dir.Write("no_newline.log", text.substr(0, text.size() - 1));
  const CarmenLog log = ReadCarmenLog(path);
  EXPECT_EQ(log.truncated, "");
  EXPECT_EQ(log.true_poses.size(), 5u);
  const std::string odd = dir.Write("comment.log", text + "# the end");
  EXPECT_EQ(ReadCarmenLog(odd).truncated, "");
}

// `slamrig simulate --out DIR` writes DIR/run.log (or the bag DIR/run): DIR names its run.
TEST(LogFolderTest, AFolderWithOneRunReadsIt) {
  TempDir dir;
  const std::string text = ReadFile(WriteTestLog(dir, 5));
  fs::create_directories(dir.File("sim"));
  WriteAll(dir.File("sim/run.log"), text);
  WriteAll(dir.File("sim/truth.tum"), "1000 0 0 0 0 0 0 1\n");
  EXPECT_EQ(ResolveLogPath(dir.File("sim")), dir.File("sim/run.log"));
  const Dataset data = ReadLog(dir.File("sim"));
  EXPECT_EQ(data.source, dir.File("sim/run.log"));
  EXPECT_EQ(data.reference.size(), 5u);

  WriteAll(dir.File("sim/other.log.gz"), "");
  EXPECT_EQ(ErrorOf([&] { ReadLog(dir.File("sim")); }),
            dir.File("sim") + ": a folder with 2 runs (" + dir.File("sim/other.log.gz") + ", " +
                dir.File("sim/run.log") + "): give one");
  fs::create_directories(dir.File("empty"));
  EXPECT_THAT(ErrorOf([&] { ReadLog(dir.File("empty")); }),
              HasSubstr(dir.File("empty") + ": a folder, but neither a ROS 2 bag"));
  EXPECT_THAT(ErrorOf([&] { ReadLog(dir.File("empty")); }), HasSubstr("and no run in it"));

  fs::create_directories(dir.File("ece"));
  WriteAll(dir.File("ece/encoders20.csv.gz"), "");
  WriteAll(dir.File("ece/imu20.csv.gz"), "");
  EXPECT_EQ(RunsInFolder(dir.File("ece")), std::vector<std::string>{dir.File("ece/20")});
}

TEST(LogFolderTest, StrictReadingRefusesACutLog) {
  TempDir dir;
  const std::string text = ReadFile(WriteTestLog(dir, 5));
  const std::string path = dir.Write("cut.log", text.substr(0, text.size() - 20));
  LogReadOptions strict;
  strict.strict = true;
  EXPECT_THAT(ErrorOf([&] { ReadLog(path, strict); }), HasSubstr(path + ":"));
  const Dataset data = ReadLog(path);
  EXPECT_THAT(data.truncated, HasSubstr(path + " truncated in line "));
  EXPECT_EQ(data.reference.size(), 4u);
}

}  // namespace
}  // namespace slamrig::slam
