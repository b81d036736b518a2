#include "slam/io/carmen_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <numbers>

#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

std::string Flaser(int n, double range, double x, double y, double th, double t) {
  std::string line = "FLASER " + std::to_string(n);
  for (int i = 0; i < n; ++i) line += " " + std::to_string(range);
  char tail[200];
  std::snprintf(tail, sizeof(tail), " %g %g %g %g %g %g %g host %g\n", x, y, th, x, y, th, t, t);
  return line + tail;
}

std::string Odom(double x, double y, double th, double t) {
  char line[200];
  std::snprintf(line, sizeof(line), "ODOM %g %g %g 0 0 0 %g host %g\n", x, y, th, t, t);
  return line;
}

std::string ErrorOf(const std::string& path, CarmenReadOptions options = {}) {
  try {
    ReadCarmenLog(path, options);
  } catch (const ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(CarmenReaderTest, ReadsFlaserOdomParamAndTruePos) {
  TempDir dir;
  const std::string path =
      dir.Write("a.log", "# comment\nPARAM robot_frontlaser_offset 0.1 nohost 0\n" +
                             Odom(0, 0, 0, 1.0) + Flaser(181, 2.5, 1.0, 2.0, 0.5, 1.1) +
                             "TRUEPOS 1.01 2.02 0.51 1 2 0.5 1.1 host 1.1\nNEFF 12\n");
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 1u);
  const LaserScan& scan = log.scans[0].scan;
  EXPECT_EQ(scan.ranges_m.size(), 181u);
  EXPECT_FLOAT_EQ(scan.ranges_m[7], 2.5f);
  EXPECT_NEAR(scan.angle_min_rad, -std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(scan.BeamAngle(180), std::numbers::pi / 2, 1e-12);  // odd count: -90..+90 deg
  EXPECT_NEAR(scan.base_from_laser.x(), 0.1, 1e-12);
  EXPECT_EQ(scan.time, Time::FromSeconds(1.1));
  EXPECT_EQ(log.scans[0].logged_pose, Pose2(1.0, 2.0, 0.5));
  EXPECT_EQ(log.scans[0].line, 4);
  ASSERT_EQ(log.odometry.size(), 1u);
  ASSERT_EQ(log.true_poses.size(), 1u);
  EXPECT_EQ(log.true_poses[0].map_from_base, Pose2(1.01, 2.02, 0.51));
  EXPECT_EQ(log.stats.unknown_messages.at("NEFF"), 1);
  EXPECT_FALSE(log.is_corrected);
  EXPECT_TRUE(log.timestamps_usable);
}

TEST(CarmenReaderTest, EvenBeamCountsSpanMinus90ToPlus89Degrees) {
  TempDir dir;
  const CarmenLog log = ReadCarmenLog(dir.Write("a.log", Flaser(180, 1.0, 0, 0, 0, 1.0)));
  const LaserScan& scan = log.scans[0].scan;
  EXPECT_NEAR(scan.BeamAngle(0), -std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(scan.BeamAngle(179), 89.0 * std::numbers::pi / 180.0, 1e-12);
}

TEST(CarmenReaderTest, DetectsGMappingEchoLinesAndSaturatedRanges) {
  TempDir dir;
  std::string text = Odom(0.1, 0, 0, 1.0);
  std::string scan = "FLASER 4 1.0 81.83 2.0 81.83 0.5 0.1 0.2 0.5 0.1 0.2 1.5 pippo 1.5\n";
  text += scan + "ODOM 0.5 0.1 0.2 0 0 0 0 pippo 0\n" + Odom(0.6, 0.1, 0.2, 2.0);
  const CarmenLog log = ReadCarmenLog(dir.Write("c.log", text));
  EXPECT_TRUE(log.is_corrected);
  EXPECT_EQ(log.odometry.size(), 2u);
  EXPECT_EQ(log.stats.skipped.begin()->second, 1);
  // 81.83 is beyond the 80 m no-return threshold.
  EXPECT_DOUBLE_EQ(log.scans[0].scan.range_max_m, 80.0);
  EXPECT_TRUE(log.scans[0].scan.IsHit(0));
  EXPECT_FALSE(log.scans[0].scan.IsHit(1));
}

TEST(CarmenReaderTest, RecurringTopReadingIsTheNoReturnValue) {
  TempDir dir;
  // ACES-like: 50.0 is the configured maximum and marks no return.
  std::string text;
  for (int i = 0; i < 5; ++i) {
    text += "FLASER 4 1.0 50.0 2.0 50.0 0 0 0 0 0 0 " + std::to_string(i + 1) + " h 1\n";
  }
  const CarmenLog log = ReadCarmenLog(dir.Write("aces.log", text));
  EXPECT_DOUBLE_EQ(log.scans[0].scan.range_max_m, 50.0);
  EXPECT_TRUE(log.scans[0].scan.IsHit(2));
  EXPECT_FALSE(log.scans[0].scan.IsHit(3));
  EXPECT_THAT(log.notes.front(), HasSubstr("no-return value"));
}

TEST(CarmenReaderTest, KeepsFileOrderWhenStampsGoBackwards) {
  TempDir dir;
  const CarmenLog log = ReadCarmenLog(
      dir.Write("o.log", Odom(0, 0, 0, 5.0) + Odom(1, 0, 0, 4.0) + Odom(2, 0, 0, 6.0)));
  ASSERT_EQ(log.odometry.size(), 3u);
  EXPECT_EQ(log.odometry[1].odometry.time, Time::FromSeconds(4.0));
  EXPECT_EQ(log.odometry[2].odometry.time, Time::FromSeconds(6.0));
  EXPECT_EQ(log.stats.out_of_order_times, 1);
}

TEST(CarmenReaderTest, SynthesizesTimesWhenStampsAreUnusable) {
  TempDir dir;
  std::string text;
  for (int i = 0; i < 10; ++i) text += Odom(i, 0, 0, 1.01893e+09);
  const CarmenLog log = ReadCarmenLog(dir.Write("u.log", text));
  EXPECT_FALSE(log.timestamps_usable);
  EXPECT_EQ(log.odometry[3].odometry.time, Time::FromSeconds(0.004));  // line 4
  ASSERT_FALSE(log.notes.empty());
  EXPECT_THAT(log.notes.back(), HasSubstr("synthesized from file order"));
}

TEST(CarmenReaderTest, ReadsRobotLaserWithItsOwnGeometry) {
  TempDir dir;
  const std::string line =
      "ROBOTLASER1 0 -2.35 4.7 0.5 30 0.01 0 3 1.5 30 2.5 0 "
      "1.2 2 0.1 1 2 0.1 0 0 0 0 0 7.25 host 7.25\n";
  const CarmenLog log = ReadCarmenLog(dir.Write("r.log", line));
  const CarmenScan& s = log.scans.at(0);
  EXPECT_DOUBLE_EQ(s.scan.angle_min_rad, -2.35);
  EXPECT_DOUBLE_EQ(s.scan.angle_increment_rad, 0.5);
  EXPECT_DOUBLE_EQ(s.scan.range_max_m, 30.0);
  EXPECT_FALSE(s.scan.IsHit(1));
  EXPECT_NEAR(s.scan.base_from_laser.x(), 0.2 * std::cos(-0.1), 1e-9);
  EXPECT_EQ(s.logged_pose, Pose2(1, 2, 0.1));
}

TEST(CarmenReaderTest, SlamrigParamsSetBeamTimingAndMinimumRange) {
  TempDir dir;
  const std::string text =
      "PARAM laser_time_increment_s 1.736111111111111e-05 slamrig 0\n"
      "PARAM laser_range_min_m 0.1 slamrig 0\n"
      "ROBOTLASER1 0 -2.35 4.7 0.5 30 0.01 0 3 1.5 0.05 2.5 0 "
      "0 0 0 0 0 0 0 0 0 0 0 7.25 host 7.25\n";
  const CarmenLog log = ReadCarmenLog(dir.Write("p.log", text));
  EXPECT_DOUBLE_EQ(log.scans[0].scan.time_increment_s, 1.736111111111111e-05);
  EXPECT_DOUBLE_EQ(log.scans[0].scan.range_min_m, 0.1);
  EXPECT_FALSE(log.scans[0].scan.IsHit(1));  // 0.05 m is under the minimum range
}

TEST(CarmenReaderTest, ReadsGzipTransparently) {
  TempDir dir;
  const std::string path = dir.File("g.log.gz");
  gzFile f = gzopen(path.c_str(), "wb");
  const std::string text = Odom(1, 2, 0.3, 1.0) + Flaser(3, 1.0, 0, 0, 0, 1.2);
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  const CarmenLog log = ReadCarmenLog(path);
  EXPECT_EQ(log.scans.size(), 1u);
  EXPECT_EQ(log.odometry[0].odometry.odom_from_base, Pose2(1, 2, 0.3));
}

TEST(CarmenReaderTest, BadInputNamesFileLineAndField) {
  TempDir dir;
  const std::string good = Odom(0, 0, 0, 1.0);
  std::string truncated = Flaser(5, 1.0, 0, 0, 0, 1.1);
  truncated.resize(truncated.size() / 2);
  EXPECT_THAT(ErrorOf(dir.Write("t.log", good + truncated + "\n")),
              HasSubstr("t.log:2: FLASER line: expected 16 fields"));
  EXPECT_THAT(ErrorOf(dir.Write("n.log", "FLASER 3 1.0 nan 1.0 0 0 0 0 0 0 1 h 1\n")),
              HasSubstr("n.log:1: FLASER range[1]: not a finite number: 'nan'"));
  EXPECT_THAT(
      ErrorOf(dir.Write("w.log", "FLASER 4 1.0 1.0 1.0 0 0 0 0 0 0 1 h 1\n")),
      HasSubstr("w.log:1: FLASER line: expected 15 fields for FLASER with 4 readings, found 14"));
  EXPECT_THAT(ErrorOf(dir.Write("x.log", "ODOM 0 0 zero 0 0 0 1 h 1\n")),
              HasSubstr("x.log:1: ODOM pose.theta: expected a number, got 'zero'"));
  EXPECT_THAT(ErrorOf(dir.Write("e.log", "")), HasSubstr("e.log: empty file"));
  EXPECT_THAT(
      ErrorOf(dir.Write("b.log", std::string("\x7f\x45\x4c\x46\x02\x01\x01\x00garbage", 15))),
      HasSubstr("b.log:1: line: binary data"));
  EXPECT_THAT(ErrorOf(dir.File("missing.log")), HasSubstr("missing.log: no such file"));
  EXPECT_THAT(ErrorOf(dir.Write("u.log", "HELLO 1 2 3\nWORLD\n")), HasSubstr("no CARMEN messages"));
  EXPECT_THAT(ErrorOf(dir.Write("neg.log", "FLASER 1 -1.0 0 0 0 0 0 0 1 h 1\n")),
              HasSubstr("range[0]: negative range"));
  // Found by fuzz/ (carmen target): a laser message without beams was accepted as a scan.
  EXPECT_THAT(ErrorOf(dir.Write("z.log", "FLASER 0 0 0 0 0 0 0 1 h 1\n")),
              HasSubstr("z.log:1: FLASER num_readings: a laser message needs at least one"));
  EXPECT_THAT(ErrorOf(dir.Write("zr.log", "RAWLASER1 0 -1.57 3.14 0.01 81.9 0.01 0 0 0 1 h 1\n")),
              HasSubstr("zr.log:1: RAWLASER1 num_readings: a laser message needs at least one"));
}

TEST(CarmenReaderTest, LenientModeCountsSkippedLines) {
  TempDir dir;
  const std::string text =
      Odom(0, 0, 0, 1.0) + "ODOM 1 2\n" + Flaser(3, 1.0, 0, 0, 0, 1.2) + "FLASER 3 1 1\n";
  CarmenReadOptions options;
  options.lenient = true;
  const CarmenLog log = ReadCarmenLog(dir.Write("l.log", text), options);
  EXPECT_EQ(log.scans.size(), 1u);
  EXPECT_EQ(log.odometry.size(), 1u);
  EXPECT_EQ(log.stats.skipped.at("malformed ODOM"), 1);
  EXPECT_EQ(log.stats.skipped.at("malformed FLASER"), 1);
}

}  // namespace
}  // namespace slamrig::slam
