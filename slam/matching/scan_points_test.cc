#include "slam/matching/scan_points.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
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

// A 360-beam full-turn scan of the inside of a circular room (radius 5 m, centred at the base
// at beam 0's time), each beam cast from where the base is when that beam is taken: the base
// drives an arc at `velocity` while the beams sweep (here integrated in small Euler steps,
// independently of LaserScan::SweepPose).
LaserScan SweptRoomScan(const BaseVelocity& velocity, double time_increment_s) {
  constexpr double kRadius = 5.0;
  LaserScan scan;
  scan.angle_min_rad = -M_PI;
  scan.angle_increment_rad = 2.0 * M_PI / 360.0;
  scan.time_increment_s = time_increment_s;
  scan.range_min_m = 0.05;
  scan.range_max_m = 30.0;
  scan.base_from_laser = Pose2(0.1, 0.05, 0.2);
  double x = 0.0, y = 0.0, yaw = 0.0;
  constexpr int kSteps = 200;  // Euler steps per beam
  for (int i = 0; i < 360; ++i) {
    const Pose2 laser = Pose2(x, y, yaw) * scan.base_from_laser;
    const double a = laser.theta() + scan.BeamAngle(static_cast<std::size_t>(i));
    const Eigen::Vector2d o = laser.translation(), d(std::cos(a), std::sin(a));
    // |o + r d| = R, r > 0.
    const double b = o.dot(d), c = o.squaredNorm() - kRadius * kRadius;
    scan.ranges_m.push_back(static_cast<float>(-b + std::sqrt(b * b - c)));
    for (int k = 0; k < kSteps; ++k) {
      const double dt = time_increment_s / kSteps;
      x += velocity.forward_m_s * std::cos(yaw) * dt;
      y += velocity.forward_m_s * std::sin(yaw) * dt;
      yaw += velocity.yaw_rate_rad_s * dt;
    }
  }
  return scan;
}

double WorstDistanceFromRoomWall(const std::vector<Eigen::Vector2d>& points) {
  double worst = 0.0;
  for (const Eigen::Vector2d& p : points) worst = std::max(worst, std::abs(p.norm() - 5.0));
  return worst;
}

TEST(ScanPointsTest, ASweepingScanIsUndistortedByTheBasesMotion) {
  // An RPLIDAR-like sweep: 0.18 s per turn while turning at 1 rad/s and driving 0.5 m/s.
  const BaseVelocity velocity{.forward_m_s = 0.5, .yaw_rate_rad_s = 1.0};
  LaserScan scan = SweptRoomScan(velocity, 0.18 / 360.0);
  // Taken as simultaneous, the far beams are off the wall by the sweep's motion (~9 cm).
  EXPECT_GT(WorstDistanceFromRoomWall(ScanToBasePoints(scan, ScanPointsOptions{})), 0.05);
  scan.sweep_velocity = velocity;
  ASSERT_TRUE(scan.Sweeps());
  const std::vector<Eigen::Vector2d> points = ScanToBasePoints(scan, ScanPointsOptions{});
  ASSERT_EQ(points.size(), 360u);
  EXPECT_LT(WorstDistanceFromRoomWall(points), 1e-4);  // float ranges, Euler steps
}

TEST(ScanPointsTest, SweepPoseIsTheIdentityWithoutATimeIncrementOrAVelocity) {
  LaserScan scan = Arc(10, 2.0f);
  scan.sweep_velocity = {.forward_m_s = 1.0, .yaw_rate_rad_s = 1.0};
  EXPECT_FALSE(scan.Sweeps());
  scan.time_increment_s = 0.01;
  EXPECT_TRUE(scan.Sweeps());
  EXPECT_TRUE(scan.SweepPose(0).translation().isZero());
  const Pose2 last = scan.SweepPose(9);  // 0.09 s at 1 m/s and 1 rad/s: a 0.09 m arc
  EXPECT_NEAR(last.theta(), 0.09, 1e-15);
  EXPECT_NEAR(last.translation().norm(), 2.0 * std::sin(0.045), 1e-15);  // the chord
  scan.sweep_velocity = {};
  EXPECT_FALSE(scan.Sweeps());
}

TEST(ScanPointsTest, ValidateNamesFieldValueAndRule) {
  ScanPointsOptions options;
  options.beam_stride = 0;
  EXPECT_THAT(options.Validate(), testing::ElementsAre("beam_stride = 0; must be >= 1"));
}

TEST(ScanPointsTest, ASparseScanKeepsItsFarReturnsAndADenseOneDoesNot) {
  // 100 beams on an 80 m lidar: k of them at 10 m, the rest at 50 m.
  auto scan_with_near = [](int k) {
    LaserScan scan = Arc(100, 50.0f);
    scan.range_max_m = 80.0;
    for (int i = 0; i < k; ++i) scan.ranges_m[static_cast<std::size_t>(i)] = 10.0f;
    return scan;
  };
  ScanPointsOptions options;  // max_range_m 30
  options.sparse_fraction = 0.25;
  for (int k = 0; k <= 100; k += 5) {
    const LaserScan scan = scan_with_near(k);
    const bool sparse = k < 25;
    EXPECT_EQ(SparseScanRange(scan, options).has_value(), sparse) << k;
    EXPECT_EQ(ScanToBasePoints(scan, options).size(), sparse ? 100u : static_cast<std::size_t>(k))
        << k;
  }
  // Off by default, and never beyond the lidar's own range.
  EXPECT_FALSE(SparseScanRange(scan_with_near(0), ScanPointsOptions{}).has_value());
  LaserScan short_lidar = scan_with_near(0);
  short_lidar.range_max_m = 20.0;
  EXPECT_FALSE(SparseScanRange(short_lidar, options).has_value());
  EXPECT_DOUBLE_EQ(*SparseScanRange(scan_with_near(0), options), 80.0);
}

}  // namespace
}  // namespace slamrig::slam
