#include "slam/pipeline/rbpf_estimator.h"

#include <gtest/gtest.h>

#include "slam/pf/testing/synthetic_run.h"
#include "slam/pipeline/estimator_runner.h"

namespace slamrig::slam {
namespace {

const std::vector<Record>& Records() { return testing::SmallOfficeRecords(); }

// Through the algorithm table, as every command runs it: one revised pose per scan, built from
// the best path and the odometry since its last update, so the last one is the online pose.
TEST(RbpfEstimatorTest, RevisesOnePosePerScanEndingAtTheOnlinePose) {
  EstimatorConfig config = DefaultEstimatorConfig("rbpf", "rbpf");
  ReadEstimatorFields(YamlNode::LoadString("particles: 10", "test"), &config);
  const EstimatorRun run = RunEstimator(config, Records(), 3);
  ASSERT_GT(run.online.size(), 100u);
  ASSERT_EQ(run.final.size(), run.online.size());
  EXPECT_EQ(run.final.poses().back().pose, run.online.poses().back().pose);
  EXPECT_EQ(run.final.poses().front().pose, Pose2());
  EXPECT_GT(run.statistics.at("updates"), 10.0);
  EXPECT_GT(run.statistics.at("map_tiles"), 0.0);
  // The map is the best particle's, converted: walls were seen.
  int occupied = 0;
  for (const float l : run.map.DenseLogOdds()) occupied += l > 0.0f;
  EXPECT_GT(occupied, 100);
}

}  // namespace
}  // namespace slamrig::slam
