// Issue 4's simulated check, end to end through the log file: the office world, default noise,
// three laps of the corridor loop (`slamrig simulate office`), then particle-filter SLAM with
// 100 particles on the written run.log must reach ATE RMSE <= 0.10 m against the simulator's
// truth and at most half of dead reckoning's on the same odometry.
#include <gtest/gtest.h>

#include "scenarios/recording.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/eval/trajectory_error.h"
#include "slam/io/log_reader.h"
#include "slam/pipeline/estimator_runner.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

TEST(PfOfficeTest, ThreeLapsWithinTenCentimetresAndHalfOfDeadReckoning) {
  testing::TempDir dir;
  sim::SimulatorOptions options;
  options.world = sim::LoadWorldSpec(sim::FindPresetFile("office", "worlds"));
  options.robot = sim::LoadRobotSpec(sim::FindPresetFile("ece276a", "robots"));
  options.seed = 1;
  ASSERT_EQ(options.world.drive.laps, 3);
  scenario::RecordSimulation(options, scenario::RunOptions{}, dir.path().string());

  const slam::Dataset data = slam::ReadLog(dir.File("run.log"));
  Trajectory truth;
  for (const GroundTruthPose& g : data.reference) truth.Append(g.time, g.map_from_base);

  const slam::EstimatorRun dr_run = slam::RunEstimator(
      slam::DefaultEstimatorConfig("dead_reckoning", "dead-reckoning"), data.records, 1);
  ASSERT_GT(dr_run.final.size(), 10000u);
  const double dr = slam::ComputeAte(dr_run.final, truth).translation_m.rmse;
  const double pf =
      slam::ComputeAte(
          slam::RunEstimator(slam::DefaultEstimatorConfig("pf", "pf"), data.records, 1).final,
          truth)
          .translation_m.rmse;
  RecordProperty("dead_reckoning_ate_rmse_m", std::to_string(dr));
  RecordProperty("pf_ate_rmse_m", std::to_string(pf));
  EXPECT_LE(pf, 0.10) << "dead reckoning " << dr;
  EXPECT_LE(pf, 0.5 * dr);
}

}  // namespace
}  // namespace slamrig
