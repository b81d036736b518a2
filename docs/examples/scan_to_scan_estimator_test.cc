#include "slam/pipeline/scan_to_scan_estimator.h"

#include <gtest/gtest.h>

#include "slam/pf/testing/synthetic_run.h"
#include "slam/pipeline/estimator_runner.h"

namespace slamrig::slam {
namespace {

// The final position error of `run` against the truth, both in the frame of the first scan.
double FinalError(const EstimatorRun& run, const testing::SyntheticRun& truth) {
  const Pose2 expected =
      truth.truth.front().map_from_base.Between(truth.truth.back().map_from_base);
  return (run.online.poses().back().pose.translation() - expected.translation()).norm();
}

// Through the algorithm table, as every command runs it: on a leg and a corner of the office
// with wheels miscalibrated by 3 %, matching the scans ends much closer to the truth than the
// odometry it starts from, and nearly every scan is matched.
TEST(ScanToScanEstimatorTest, EndsCloserToTheTruthThanDeadReckoning) {
  const testing::SyntheticRun& office = testing::GetShortOfficeRun().run;
  const EstimatorRun odometry =
      RunEstimator(DefaultEstimatorConfig("odometry", "dead-reckoning"), office.records, 1);
  const EstimatorRun matched =
      RunEstimator(DefaultEstimatorConfig("s2s", "scan-to-scan"), office.records, 1);
  ASSERT_EQ(matched.online.size(), office.truth.size());
  EXPECT_LT(FinalError(matched, office), 0.5 * FinalError(odometry, office));
  EXPECT_GT(matched.statistics.at("matched"), 0.9 * static_cast<double>(matched.online.size()));
}

}  // namespace
}  // namespace slamrig::slam
