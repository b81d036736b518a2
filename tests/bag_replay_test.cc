// docs/architecture.md's missing test: simulate, write a log, read it back, and get bit-identical
// SLAM output. A scenario runs in process on the simulator; the same simulation recorded as a ROS 2
// bag (MCAP with renamed topics, and sqlite3) replays through the same estimators; every pose,
// trace and statistic must be equal bit for bit.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "scenarios/recording.h"
#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "slam/io/bag/bag_reader.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

constexpr double kDurationS = 30.0;
constexpr const char* kSlam =
    "seed: 4\n"
    "robot: ece276a\n"
    "duration_s: 30\n"
    "slam:\n"
    "  dead_reckoning: {algorithm: dead-reckoning}\n"
    "  pf: {algorithm: pf, particles: 20}\n";

std::string WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

// Bitwise equality of doubles (EXPECT_EQ would call -0.0 and 0.0 equal).
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void ExpectSameTrajectory(const Trajectory& a, const Trajectory& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].time, b[i].time) << what << " pose " << i;
    ASSERT_TRUE(SameBits(a[i].pose.x(), b[i].pose.x()) && SameBits(a[i].pose.y(), b[i].pose.y()) &&
                SameBits(a[i].pose.theta(), b[i].pose.theta()))
        << what << " pose " << i << ": " << a[i].pose.x() << " " << a[i].pose.y() << " "
        << a[i].pose.theta() << " vs " << b[i].pose.x() << " " << b[i].pose.y() << " "
        << b[i].pose.theta();
  }
}

class BagReplayTest : public testing::TestWithParam<RecordingFormat> {};

TEST_P(BagReplayTest, ReplayedBagGivesBitIdenticalSlamOutput) {
  const std::string dir =
      testing::TempDir() + "/bag_replay_" + std::to_string(static_cast<int>(GetParam()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const ScenarioSpec in_process = LoadScenario(
      WriteFile(dir + "/sim.yaml", std::string("name: replay_sim\nworld: office\n") + kSlam));
  ASSERT_TRUE(in_process.simulated);

  // The very simulation the scenario runs, recorded to a bag.
  RunOptions run;
  run.duration_s = kDurationS;
  RecordingOptions recording;
  recording.format = GetParam();
  // The MCAP bag renames two topics, which the log scenario then names (source.topics).
  std::string topics;
  if (GetParam() == RecordingFormat::kMcap) {
    recording.topics.scan = "/front/scan";
    recording.topics.joint_states = "/wheels/joint_states";
    topics = ", topics: {scan: /front/scan, joint_states: /wheels/joint_states}";
  }
  const RunSummary summary =
      RecordSimulation(in_process.simulated->options, run, dir + "/rec", recording);
  const ScenarioSpec replay = LoadScenario(WriteFile(
      dir + "/log.yaml",
      "name: replay_log\nsource: {log: " + summary.files[0] + topics + "}\n" + std::string(kSlam)));
  ASSERT_TRUE(replay.log);

  // base_from_laser goes through /tf_static and comes back exactly.
  const Pose2 mount = in_process.simulated->options.robot.lidar.mount.ToPose2();
  slam::BagReaderOptions read;
  read.topics = replay.log->read.topics;
  int scans = 0;
  for (const Record& r : slam::ReadBag(summary.files[0], read).records) {
    if (const auto* scan = std::get_if<LaserScan>(&r)) {
      ++scans;
      ASSERT_TRUE(SameBits(scan->base_from_laser.x(), mount.x()) &&
                  SameBits(scan->base_from_laser.y(), mount.y()) &&
                  SameBits(scan->base_from_laser.theta(), mount.theta()));
    }
  }
  EXPECT_EQ(scans, summary.num_scans);

  const ScenarioResult a = RunScenario(in_process);
  const ScenarioResult b = RunScenario(replay);
  ASSERT_GT(a.scans, 1000);
  EXPECT_EQ(a.scans, b.scans);
  EXPECT_EQ(a.scans, summary.num_scans);
  ExpectSameTrajectory(a.truth, b.truth, "truth");
  ASSERT_EQ(a.configs.size(), 2u);
  ASSERT_EQ(b.configs.size(), 2u);
  for (std::size_t c = 0; c < a.configs.size(); ++c) {
    const slam::EstimatorRun& x = a.configs[c].run;
    const slam::EstimatorRun& y = b.configs[c].run;
    SCOPED_TRACE(x.name);
    // The replay integrates the same wheel ticks and gyro, not the bag's /odom quaternions.
    EXPECT_EQ(x.odometry_source, slam::OdometrySource::kWheelTicks);
    EXPECT_EQ(y.odometry_source, x.odometry_source);
    ExpectSameTrajectory(x.online, y.online, "online");
    ExpectSameTrajectory(x.final, y.final, "final");
    ExpectSameTrajectory(x.mean, y.mean, "mean");
    EXPECT_EQ(x.gyro_fallbacks, y.gyro_fallbacks);
    ASSERT_EQ(x.statistics.size(), y.statistics.size());
    for (const auto& [name, value] : x.statistics) {
      EXPECT_TRUE(SameBits(value, y.statistics.at(name))) << name;
    }
    ASSERT_EQ(x.traces.size(), y.traces.size());
    for (const auto& [name, values] : x.traces) {
      const std::vector<double>& other = y.traces.at(name);
      ASSERT_EQ(values.size(), other.size()) << name;
      for (std::size_t i = 0; i < values.size(); ++i) {
        ASSERT_TRUE(SameBits(values[i], other[i])) << name << "[" << i << "]";
      }
    }
    // The same map, cell for cell.
    EXPECT_EQ(x.map.width(), y.map.width());
    EXPECT_EQ(x.map.height(), y.map.height());
    EXPECT_TRUE(x.map.DenseLogOdds() == y.map.DenseLogOdds());
  }
  // The PF did real work: a trajectory that moved, not an empty comparison.
  EXPECT_GT(a.configs[1].run.online.size(), 1000u);
}

INSTANTIATE_TEST_SUITE_P(Storages, BagReplayTest,
                         testing::Values(RecordingFormat::kMcap, RecordingFormat::kSqlite3),
                         [](const testing::TestParamInfo<RecordingFormat>& param) {
                           return param.param == RecordingFormat::kMcap ? "mcap" : "sqlite3";
                         });

}  // namespace
}  // namespace slamrig::scenario
