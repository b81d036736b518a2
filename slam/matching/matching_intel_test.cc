// The matchers on a real log, intel-corrected (910 scans, 180 beams): its GMapping-corrected poses
// are the reference.
#include <gtest/gtest.h>

#include <cmath>

#include "slam/io/carmen_reader.h"
#include "slam/io/dataset.h"
#include "slam/matching/correlative_matcher.h"
#include "slam/matching/icp_odometry.h"
#include "slam/matching/scan_points.h"
#include "slam/odometry/gaussian.h"
#include "slam/odometry/scan_sync.h"
#include "tests/util/dataset.h"

namespace slamrig::slam {
namespace {

// Loop closure against the map of the other visits: a scan, with the scans within 60 of it left
// out of the map, is found from metres and radians away in a +-7 m, +-pi window.
TEST(MatchingIntelTest, CorrelativeSearchFindsScansInTheMapOfOtherVisits) {
  SLAMRIG_REQUIRE_DATASET(path, "carmen_corrected/intel-corrected.log.gz");
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 910u);
  RandomEngine rng(31);
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  CorrelativeMatcherOptions options;
  options.min_score = 0.4;
  int found = 0;
  for (const std::size_t k : {150u, 400u, 650u, 880u}) {
    OccupancyGrid grid{OccupancyGridOptions{}};
    for (std::size_t i = 0; i < log.scans.size(); ++i) {
      if (i + 60 < k || i > k + 60) grid.InsertScan(log.scans[i].scan, log.scans[i].logged_pose);
    }
    const CorrelativeMatcher matcher(options, grid);
    const Pose2 truth = log.scans[k].logged_pose;
    const Eigen::Vector3d d = Uniform3(rng);
    const Pose2 initial(truth.x() + 8.0 * d.x() - 4.0, truth.y() + 8.0 * d.y() - 4.0,
                        truth.theta() + 6.0 * d.z() - 3.0);
    const std::optional<MatchResult> m =
        matcher.Match(ScanToBasePoints(log.scans[k].scan, points), initial);
    if (!m) continue;  // a place seen only on this visit: no loop closure, which is right
    ++found;
    EXPECT_LT((m->pose.translation() - truth.translation()).norm(), 0.15) << k;
    EXPECT_LT(std::abs(NormalizeAngle(m->pose.theta() - truth.theta())), 0.03) << k;
  }
  EXPECT_GE(found, 3);
}

// ICP odometry over the whole log: per step, far closer to the corrected poses than the raw
// odometry it starts from.
TEST(MatchingIntelTest, IcpOdometryBeatsTheRawOdometryPerStep) {
  SLAMRIG_REQUIRE_DATASET(path, "carmen_corrected/intel-corrected.log.gz");
  const CarmenLog log = ReadCarmenLog(path);
  const std::vector<SyncedScan> synced =
      SyncToScans(CarmenToDataset(log).records, ScanSyncOptions{}).scans;
  ASSERT_EQ(synced.size(), log.scans.size());
  IcpOdometry icp{IcpOdometryOptions{}};
  std::vector<Pose2> estimate;
  for (const SyncedScan& s : synced) estimate.push_back(icp.Add(s.scan, s.increment).pose);
  const std::vector<Pose2> odometry = DeadReckoningPoses(synced);
  auto step_errors = [&](const std::vector<Pose2>& poses) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();  // translation (m), yaw (rad)
    for (std::size_t k = 1; k < poses.size(); ++k) {
      const Pose2 e = log.scans[k - 1]
                          .logged_pose.Between(log.scans[k].logged_pose)
                          .Between(poses[k - 1].Between(poses[k]));
      sum += Eigen::Vector2d(e.translation().norm(), std::abs(e.theta()));
    }
    return Eigen::Vector2d(sum / static_cast<double>(poses.size() - 1));
  };
  const Eigen::Vector2d icp_error = step_errors(estimate), odometry_error = step_errors(odometry);
  EXPECT_LT(icp_error.x(), 0.6 * odometry_error.x());
  EXPECT_LT(icp_error.y(), 0.3 * odometry_error.y());
  EXPECT_GT(icp.counts().matched, 900);
}

}  // namespace
}  // namespace slamrig::slam
