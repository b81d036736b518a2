#include "slam/matching/scan_points.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace slamrig::slam {
namespace {

LaserScan Arc(int n, float range) {
  LaserScan scan;
  scan.angle_min_rad = -1.0;
  scan.angle_increment_rad = 2.0 / (n - 1);
  scan.range_min_m = 0.05;
  scan.range_max_m = 30.0;
  scan.ranges_m.assign(static_cast<std::size_t>(n), range);
  return scan;
}

TEST(ScanPointsTest, AppliesTheLaserMountAndDropsInvalidBeams) {
  LaserScan scan = Arc(3, 2.0f);
  scan.ranges_m[1] = 30.0f;  // no return
  scan.base_from_laser = Pose2(0.5, 0.0, 0.0);
  const std::vector<Eigen::Vector2d> points = ScanToBasePoints(scan, ScanPointsOptions{});
  ASSERT_EQ(points.size(), 2u);
  EXPECT_NEAR(points[0].x(), 0.5 + 2.0 * std::cos(-1.0), 1e-6);
  EXPECT_NEAR(points[0].y(), 2.0 * std::sin(-1.0), 1e-6);
}

TEST(ScanPointsTest, StrideKeepsEveryNthBeam) {
  ScanPointsOptions options;
  options.beam_stride = 4;
  EXPECT_EQ(ScanToBasePoints(Arc(101, 2.0f), options).size(), 26u);
}

TEST(ScanPointsTest, VoxelFilterKeepsOnePointPerVoxelInBeamOrder) {
  ScanPointsOptions options;
  options.voxel_size_m = 0.1;
  const LaserScan scan = Arc(1001, 0.5f);  // 1001 beams on a 1 m long arc: ~10 per voxel
  const std::vector<Eigen::Vector2d> all = ScanToBasePoints(scan, ScanPointsOptions{});
  const std::vector<Eigen::Vector2d> kept = ScanToBasePoints(scan, options);
  std::set<std::pair<long, long>> voxels;
  for (const auto& p : all)
    voxels.insert({std::lround(std::floor(p.x() / 0.1)), std::lround(std::floor(p.y() / 0.1))});
  EXPECT_EQ(kept.size(), voxels.size());
  for (std::size_t i = 1; i < kept.size(); ++i) {
    EXPECT_LT(std::atan2(kept[i - 1].y(), kept[i - 1].x()), std::atan2(kept[i].y(), kept[i].x()));
  }
}

TEST(ScanPointsTest, ValidateNamesFieldValueAndRule) {
  ScanPointsOptions options;
  options.beam_stride = 0;
  EXPECT_THAT(options.Validate(), testing::ElementsAre("beam_stride = 0; must be >= 1"));
}

}  // namespace
}  // namespace slamrig::slam
