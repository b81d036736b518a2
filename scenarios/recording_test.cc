#include "scenarios/recording.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/presets.h"
#include "sim/world_yaml.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/tum_io.h"

namespace slamrig::scenario {
namespace {

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

sim::SimulatorOptions Office(std::uint64_t seed) {
  sim::SimulatorOptions o;
  o.world = sim::LoadWorldSpec(sim::FindPresetFile("office", "worlds"));
  o.seed = seed;
  return o;
}

RunSummary WriteRun(std::uint64_t seed, const std::string& name) {
  RunOptions run;
  run.duration_s = 3.0;
  return RecordSimulation(Office(seed), run, testing::TempDir() + "/" + name);
}

TEST(RunWriterTest, SameSeedByteIdenticalFilesOtherSeedOtherNoise) {
  const RunSummary a = WriteRun(7, "run_a"), b = WriteRun(7, "run_b"), c = WriteRun(8, "run_c");
  ASSERT_EQ(a.files.size(), 5u);
  for (std::size_t i = 0; i < a.files.size(); ++i) {
    const std::string bytes = Slurp(a.files[i]);
    EXPECT_FALSE(bytes.empty()) << a.files[i];
    EXPECT_EQ(bytes, Slurp(b.files[i])) << a.files[i];
  }
  // Another seed: other sensor noise in the log, but the same physics, so the same truth.
  EXPECT_NE(Slurp(a.files[0]), Slurp(c.files[0]));
  EXPECT_EQ(Slurp(a.files[1]), Slurp(c.files[1]));
}

TEST(RunWriterTest, OurCarmenReaderReadsTheLogBack) {
  const RunSummary summary = WriteRun(3, "run_read");
  const slam::CarmenLog log = slam::ReadCarmenLog(summary.files[0]);
  EXPECT_EQ(static_cast<int>(log.scans.size()), summary.num_scans);
  EXPECT_EQ(static_cast<int>(log.odometry.size()), summary.num_odometry);
  EXPECT_EQ(log.true_poses.size(), log.scans.size());
  EXPECT_EQ(log.params.at("slamrig_world"), "office");
  ASSERT_FALSE(log.scans.empty());
  const LaserScan& scan = log.scans.front().scan;
  EXPECT_EQ(scan.ranges_m.size(), 1081u);
  EXPECT_NEAR(scan.angle_increment_rad, 0.25 * 3.141592653589793 / 180.0, 1e-15);
  EXPECT_NEAR(scan.base_from_laser.x(), 0.133, 1e-12);
  // The truth file holds the same poses as the TRUEPOS lines.
  const Trajectory truth = slam::ReadTum(summary.files[1]);
  ASSERT_EQ(truth.size(), log.true_poses.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(truth[i].time, log.true_poses[i].time);
    EXPECT_NEAR(truth[i].pose.x(), log.true_poses[i].map_from_base.x(), 1e-9);
  }
  // The odometry starts at the identity and follows the robot forwards along the corridor.
  EXPECT_GT(log.odometry.back().odometry.odom_from_base.x(), 0.5);
  EXPECT_LT(std::abs(log.odometry.back().odometry.odom_from_base.y()), 0.05);
}

}  // namespace
}  // namespace slamrig::scenario
