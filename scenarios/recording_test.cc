#include "scenarios/recording.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "sim/presets.h"
#include "sim/world_yaml.h"
#include "slam/io/bag/bag_reader.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/tum_io.h"
#include "slam/odometry/wheel_odometry.h"
#include "tests/util/read_file.h"

namespace slamrig::scenario {
namespace {

using slamrig::testing::ReadFile;

sim::SimulatorOptions Office(std::uint64_t seed) {
  sim::SimulatorOptions o;
  o.world = sim::LoadWorldSpec(sim::FindPresetFile("office", "worlds"));
  o.seed = seed;
  return o;
}

RunSummary WriteRun(std::uint64_t seed, const std::string& name) {
  RunOptions run;
  run.duration_s = 3.0;
  return RecordSimulation(Office(seed), run, ::testing::TempDir() + "/" + name);
}

TEST(RunWriterTest, SameSeedByteIdenticalFilesOtherSeedOtherNoise) {
  const RunSummary a = WriteRun(7, "run_a"), b = WriteRun(7, "run_b"), c = WriteRun(8, "run_c");
  ASSERT_EQ(a.files.size(), 5u);
  for (std::size_t i = 0; i < a.files.size(); ++i) {
    const std::string bytes = ReadFile(a.files[i]);
    EXPECT_FALSE(bytes.empty()) << a.files[i];
    EXPECT_EQ(bytes, ReadFile(b.files[i])) << a.files[i];
  }
  // Another seed: other sensor noise in the log, but the same physics, so the same truth.
  EXPECT_NE(ReadFile(a.files[0]), ReadFile(c.files[0]));
  EXPECT_EQ(ReadFile(a.files[1]), ReadFile(c.files[1]));
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
  // The simulator states scan metadata as the floats a ROS LaserScan carries.
  EXPECT_NEAR(scan.angle_increment_rad,
              static_cast<double>(static_cast<float>(0.25 * 3.141592653589793 / 180.0)), 1e-15);
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

namespace slamrig::scenario {
namespace {

RunSummary WriteBagRun(std::uint64_t seed, const std::string& name, RecordingFormat format) {
  RunOptions run;
  run.duration_s = 3.0;
  RecordingOptions recording;
  recording.format = format;
  return RecordSimulation(Office(seed), run, ::testing::TempDir() + "/" + name, recording);
}

TEST(RunWriterTest, BagsHoldTheSameRunAsTheCarmenLog) {
  const RunSummary carmen = WriteRun(5, "run_fmt_carmen");
  for (const RecordingFormat format : {RecordingFormat::kMcap, RecordingFormat::kSqlite3}) {
    const std::string name = format == RecordingFormat::kMcap ? "run_fmt_mcap" : "run_fmt_db3";
    const RunSummary bag = WriteBagRun(5, name, format);
    ASSERT_EQ(bag.files.size(), 5u);
    EXPECT_EQ(std::filesystem::path(bag.files[0]).filename(), "run");
    // truth.tum and the yaml files do not depend on the format.
    for (std::size_t i = 1; i < bag.files.size(); ++i) {
      EXPECT_EQ(ReadFile(bag.files[i]), ReadFile(carmen.files[i])) << bag.files[i];
    }
    EXPECT_EQ(bag.num_scans, carmen.num_scans);
    EXPECT_EQ(bag.num_odometry, carmen.num_odometry);
    EXPECT_EQ(bag.num_imu, carmen.num_imu);
    // One odometry computation for both sinks: the same robot estimate, bit for bit.
    EXPECT_EQ(bag.final_odometry, carmen.final_odometry);

    const slam::Dataset data = slam::ReadBag(bag.files[0]);
    int scans = 0, ticks = 0, poses = 0;
    slam::WheelOdometryOptions odometry_options;
    odometry_options.robot = sim::NominalOdometry(Office(5).robot);
    odometry_options.use_gyro = true;
    slam::WheelOdometry odometry(odometry_options);
    for (const Record& r : data.records) {
      scans += std::holds_alternative<LaserScan>(r) ? 1 : 0;
      if (const auto* imu = std::get_if<ImuSample>(&r)) odometry.AddImu(*imu);
      if (const auto* t = std::get_if<WheelTicks>(&r)) {
        odometry.AddTicks(*t);
        ++ticks;
      }
      if (const auto* p = std::get_if<OdometryPose>(&r)) {
        // /odom is the integration of the ticks before it (up to the quaternion's yaw).
        EXPECT_NEAR(p->odom_from_base.x(), odometry.pose().x(), 1e-12);
        EXPECT_NEAR(p->odom_from_base.y(), odometry.pose().y(), 1e-12);
        EXPECT_NEAR(p->odom_from_base.theta(), odometry.pose().theta(), 1e-12);
        ++poses;
      }
    }
    EXPECT_EQ(scans, bag.num_scans);
    EXPECT_EQ(ticks, bag.num_odometry);
    EXPECT_EQ(poses, bag.num_odometry);
    // The truth at every scan, as truth.tum has it.
    const Trajectory truth = slam::ReadTum(bag.files[1]);
    ASSERT_EQ(data.reference.size(), truth.size());
    EXPECT_EQ(data.reference.back().time, truth.poses().back().time);
  }
  // The same seed again: the same bag bytes.
  const RunSummary again = WriteBagRun(5, "run_fmt_mcap_again", RecordingFormat::kMcap);
  const std::string mcap = "/run_0.mcap";
  EXPECT_EQ(ReadFile(again.files[0] + mcap),
            ReadFile(::testing::TempDir() + "/run_fmt_mcap/run" + mcap));
}

}  // namespace
}  // namespace slamrig::scenario
