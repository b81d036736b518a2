#include "slam/eval/trajectory_error.h"

#include <gtest/gtest.h>

#include <cmath>

#include "slam/eval/trajectory_metrics.h"
#include "slam/odometry/gaussian.h"

namespace slamrig::slam {
namespace {

Trajectory RandomWalk(RandomEngine& rng, int n) {
  Trajectory t;
  Pose2 pose;
  for (int i = 0; i < n; ++i) {
    t.Append(Time::FromSeconds(0.1 * i), pose);
    const double turn = 0.3 * StandardNormal(rng);  // drawn first: the order of these walks
    pose = pose * Pose2(0.2 + 0.1 * Uniform01(rng), 0.0, turn);
  }
  return t;
}

Trajectory Transformed(const Trajectory& t, const Pose2& a_from_b) {
  Trajectory out;
  for (const StampedPose& p : t.poses()) out.Append(p.time, a_from_b * p.pose);
  return out;
}

// A rigidly moved copy has zero ATE, and the alignment found is the inverse motion.
TEST(TrajectoryErrorTest, AteIsZeroForARigidlyMovedCopyAndFindsTheMotion) {
  RandomEngine rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const Trajectory reference = RandomWalk(rng, 60);
    const Eigen::Vector3d n = StandardNormal3(rng);
    const Pose2 motion(10 * n.x(), 10 * n.y(), 3 * n.z());
    const AteResult ate = ComputeAte(Transformed(reference, motion), reference);
    ASSERT_EQ(ate.translation_m.count, 60);
    ASSERT_LT(ate.translation_m.max, 1e-9);
    ASSERT_LT(ate.rotation_rad.max, 1e-9);
    const Pose2 expected = motion.Inverse();
    ASSERT_NEAR(ate.reference_from_estimate.x(), expected.x(), 1e-9);
    ASSERT_NEAR(ate.reference_from_estimate.y(), expected.y(), 1e-9);
    ASSERT_NEAR(NormalizeAngle(ate.reference_from_estimate.theta() - expected.theta()), 0.0, 1e-9);
  }
}

// Zero-mean noise on a rigidly moved copy: the alignment can only lower the error, and the ATE
// stays close to the noise's own RMS.
TEST(TrajectoryErrorTest, AteOfNoisyCopyIsTheNoiseRms) {
  RandomEngine rng(8);
  const Trajectory reference = RandomWalk(rng, 2000);
  Trajectory noisy;
  double sum_sq = 0.0;
  for (const StampedPose& p : reference.poses()) {
    const double dx = 0.05 * StandardNormal(rng), dy = 0.05 * StandardNormal(rng);
    sum_sq += dx * dx + dy * dy;
    noisy.Append(p.time, Pose2(p.pose.x() + dx, p.pose.y() + dy, p.pose.theta()));
  }
  const double noise_rms = std::sqrt(sum_sq / 2000.0);
  const AteResult ate = ComputeAte(Transformed(noisy, Pose2(3.0, -2.0, 1.0)), reference);
  EXPECT_LE(ate.translation_m.rmse, noise_rms + 1e-12);
  EXPECT_NEAR(ate.translation_m.rmse, noise_rms, 0.002);
}

TEST(TrajectoryErrorTest, ReferenceIsInterpolatedAtEstimateTimes) {
  Trajectory reference;
  for (int i = 0; i <= 10; ++i) reference.Append(Time::FromSeconds(i), Pose2(i, 0.0, 0.0));
  Trajectory estimate;
  estimate.Append(Time::FromSeconds(0.5), Pose2(0.5, 0.1, 0.0));
  estimate.Append(Time::FromSeconds(4.25), Pose2(4.25, 0.1, 0.0));
  estimate.Append(Time::FromSeconds(11.0), Pose2(11.0, 0.0, 0.0));  // outside: left out
  const std::vector<PosePair> pairs = AssociatePoses(estimate, reference);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_NEAR(pairs[1].reference.x(), 4.25, 1e-12);
  AssociationOptions strict;
  strict.max_interpolation_gap_s = 0.5;
  EXPECT_TRUE(AssociatePoses(estimate, reference, strict).empty());
}

// Repeated stamps (logs with out-of-order times, clamped) pair by index, not by time.
TEST(TrajectoryErrorTest, RepeatedStampsPairByIndex) {
  Trajectory reference, estimate;
  for (int i = 0; i < 4; ++i) {
    const Time t = Time::FromSeconds(i < 2 ? 0.0 : 1.0 * i);
    reference.Append(t, Pose2(i, 0, 0));
    estimate.Append(t, Pose2(i, 0, 0));
  }
  EXPECT_LT(ComputeAte(estimate, reference).translation_m.max, 1e-12);
}

// Every step of the estimate is 10 % long: per-scan RPE is 10 % of the step, and over 1 m it is
// 10 % of the first pair spacing reaching 1 m.
TEST(TrajectoryErrorTest, RpeMeasuresRelativeScaleError) {
  Trajectory reference, estimate;
  for (int i = 0; i <= 100; ++i) {
    reference.Append(Time::FromSeconds(i), Pose2(0.3 * i, 0.0, 0.0));
    estimate.Append(Time::FromSeconds(i), Pose2(0.33 * i, 0.0, 0.0));
  }
  const RpeResult per_scan = ComputeRpe(estimate, reference, 0.0);
  EXPECT_EQ(per_scan.translation_m.count, 100);
  EXPECT_NEAR(per_scan.translation_m.mean, 0.03, 1e-9);
  EXPECT_NEAR(per_scan.translation_m.max, 0.03, 1e-9);
  const RpeResult one_metre = ComputeRpe(estimate, reference, 1.0);
  EXPECT_NEAR(one_metre.translation_m.mean, 0.12, 1e-9);  // 4 steps of 0.3 m reach 1 m
  EXPECT_EQ(one_metre.translation_m.count, 97);
  const TrajectoryMetrics m = EvaluateTrajectory(estimate, reference);
  EXPECT_NEAR(m.rpe_10m.translation_m.mean, 34 * 0.3 * 0.1, 1e-9);  // 34 steps reach 10 m
}

}  // namespace
}  // namespace slamrig::slam
