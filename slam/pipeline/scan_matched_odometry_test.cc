#include "slam/pipeline/scan_matched_odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

// Scans triggered by motion, as in the corrected CARMEN logs: one after 0.7 to 1.1 m of travel or
// about half a radian of turning, at intervals of 0.8 to 5 s that say nothing about the motion.
struct TriggeredRun {
  std::vector<Pose2> truth;
  std::vector<double> dt_s;
};

TriggeredRun OfficeLapTriggeredByMotion(RandomEngine& rng) {
  const Eigen::Vector2d corners[] = {
      {1.5, 1.5}, {18.5, 1.5}, {18.5, 10.5}, {1.5, 10.5}, {1.5, 1.5}};
  std::uniform_real_distribution<double> step(0.7, 1.1), interval(0.8, 5.0);
  TriggeredRun run;
  double yaw = 0.0;
  for (int side = 0; side < 4; ++side) {
    const Eigen::Vector2d a = corners[side], b = corners[side + 1];
    const double length = (b - a).norm();
    for (double s = 0.0; s < length - 0.3; s += step(rng)) {
      const Eigen::Vector2d p = a + (b - a) * (s / length);
      run.truth.emplace_back(p.x(), p.y(), yaw);
      run.dt_s.push_back(run.truth.size() == 1 ? 0.0 : interval(rng));
    }
    for (int t = 0; t < 3; ++t) {
      run.truth.emplace_back(b.x(), b.y(), yaw + std::numbers::pi / 2.0 * (t / 3.0));
      run.dt_s.push_back(interval(rng));
    }
    yaw += std::numbers::pi / 2.0;
  }
  return run;
}

// A 270-degree scanner at 0.75 degrees: what the corrected logs' scanners see, and quick.
SyncedScan ScanAt(const SegmentWorld& world, const Pose2& pose, double dt_s, RandomEngine& rng) {
  RangeFinderSpec spec;
  spec.num_beams = 361;
  spec.angle_increment_rad = 0.75 * std::numbers::pi / 180.0;
  SyncedScan scan;
  scan.scan = world.Scan(pose, Time(), spec, &rng);
  scan.dt_s = dt_s;
  return scan;
}

// A lap of the office with scans a metre apart at irregular intervals and no odometry at all:
// nearly every increment is recovered from the scans alone, and the lap closes within decimetres.
TEST(ScanMatchedOdometryTest, RecoversMotionTriggeredStepsWithoutOdometry) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(5);
  const TriggeredRun run = OfficeLapTriggeredByMotion(rng);
  ScanMatchedOdometry odometry;
  int close = 0;
  Pose2 estimate;
  for (std::size_t k = 0; k < run.truth.size(); ++k) {
    const SyncedScan out = odometry.Apply(ScanAt(world, run.truth[k], run.dt_s[k], rng));
    estimate = out.odom_from_base;
    if (k == 0) continue;
    const Pose2 truth = run.truth[k - 1].Between(run.truth[k]);
    const Pose2 error = truth.Between(out.increment);
    close += error.translation().norm() < 0.05 && std::abs(error.theta()) < 0.02;
    EXPECT_NEAR(std::abs(out.distance_m), out.increment.translation().norm(), 1e-12);
  }
  const int steps = static_cast<int>(run.truth.size()) - 1;
  EXPECT_GT(steps, 60);
  EXPECT_GE(close, steps * 95 / 100) << close << " of " << steps;
  const Pose2 end = run.truth.front() * estimate;
  EXPECT_LT((end.translation() - run.truth.back().translation()).norm(), 0.2);
  EXPECT_GE(odometry.counts().matched, steps * 95 / 100);
}

// A 2 m wide corridor along x with pillars (0.3 m boxes on its left wall) every `spacing_m` from
// x = -98 up to `pillars_to_x`, and bare walls beyond.
SegmentWorld PillaredCorridor(double spacing_m, double pillars_to_x) {
  SegmentWorld corridor({{{-100.0, 1.0}, {100.0, 1.0}}, {{-100.0, -1.0}, {100.0, -1.0}}});
  for (double x = -98.0; x < pillars_to_x; x += spacing_m) corridor.AddBox(x, 0.7, x + 0.3, 1.0);
  return corridor;
}

// A corridor with pillars along its first 30 m, then 20 m of bare walls: once the scans cannot
// tell how far the robot went, the prediction (its last speed) carries it on, rather than the
// seed that fits the map best, standing still.
TEST(ScanMatchedOdometryTest, KeepsItsSpeedWhereTheCorridorCannotTell) {
  const SegmentWorld corridor = PillaredCorridor(4.0, -70.0);
  RandomEngine rng(11);
  ScanMatchedOdometry odometry;
  Pose2 truth(-99.0, 0.1, 0.0);
  const Pose2 start = truth;
  Pose2 estimate;
  for (int k = 0; k < 100; ++k) {
    if (k > 0) truth = truth * Pose2(0.5, 0.0, 0.0);
    estimate = odometry.Apply(ScanAt(corridor, truth, k == 0 ? 0.0 : 1.0, rng)).odom_from_base;
  }
  // 49.5 m, the last ~20 m with no pillar within the scanner's 30 m.
  const Pose2 end = start * estimate;
  EXPECT_NEAR(end.x(), truth.x(), 0.02 * (truth.x() - start.x()));
  EXPECT_NEAR(end.y(), truth.y(), 0.05);
}

// Five scans with no return at all (the scanner blinded, a glass front) along a corridor with
// pillars: the robot coasts at its last matched speed through them and the next scan matches
// again. Predicted still, it would be 2.5 m past its prediction when the scans came back, beyond
// the window, and every later match would fail (it ended 6.8 m short).
TEST(ScanMatchedOdometryTest, CoastsThroughScansThatCannotMatch) {
  const SegmentWorld corridor = PillaredCorridor(1.7, -40.0);
  RandomEngine rng(13);
  ScanMatchedOdometry odometry;
  Pose2 truth(-99.0, 0.1, 0.0);
  const Pose2 start = truth;
  Pose2 estimate;
  for (int k = 0; k < 60; ++k) {
    if (k > 0) truth = truth * Pose2(0.5, 0.0, 0.0);
    SyncedScan scan = ScanAt(corridor, truth, k == 0 ? 0.0 : 1.0, rng);
    if (k >= 20 && k < 25) {
      for (float& r : scan.scan.ranges_m) r = static_cast<float>(scan.scan.range_max_m);
    }
    estimate = odometry.Apply(scan).odom_from_base;
  }
  const Pose2 end = start * estimate;
  EXPECT_NEAR(end.x(), truth.x(), 0.2);
  EXPECT_NEAR(end.y(), truth.y(), 0.05);
  EXPECT_EQ(odometry.counts().no_points, 5);
  EXPECT_GE(odometry.counts().matched + odometry.counts().degenerate, 54);
}

// Same scans, same bits.
TEST(ScanMatchedOdometryTest, SameScansSameBits) {
  const SegmentWorld world = SegmentWorld::Office();
  auto lap = [&] {
    RandomEngine rng(3);
    const TriggeredRun run = OfficeLapTriggeredByMotion(rng);
    ScanMatchedOdometry odometry;
    std::vector<Pose2> poses;
    for (std::size_t k = 0; k < 8; ++k) {
      poses.push_back(odometry.Apply(ScanAt(world, run.truth[k], run.dt_s[k], rng)).odom_from_base);
    }
    return poses;
  };
  const std::vector<Pose2> first = lap();
  EXPECT_EQ(first, lap());
}

}  // namespace
}  // namespace slamrig::slam
