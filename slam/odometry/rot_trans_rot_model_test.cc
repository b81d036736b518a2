#include "slam/odometry/rot_trans_rot_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

void ExpectPoseNear(const Pose2& a, const Pose2& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol);
  EXPECT_NEAR(a.y(), b.y(), tol);
  EXPECT_NEAR(NormalizeAngle(a.theta() - b.theta()), 0.0, tol);
}

TEST(RotTransRotTest, DecomposeComposeRoundTripsRandomIncrements) {
  RandomEngine rng(7);
  for (int trial = 0; trial < 10000; ++trial) {
    const Eigen::Vector3d n = StandardNormal3(rng);
    const Pose2 increment(2.0 * n.x(), 2.0 * n.y(), 3.0 * n.z());
    const RotTransRot m = RotTransRot::FromIncrement(increment);
    ASSERT_LE(std::abs(m.rot1_rad), 0.5 * std::numbers::pi + 1e-12);
    const Pose2 back = m.ToIncrement();
    ASSERT_NEAR(back.x(), increment.x(), 1e-9);
    ASSERT_NEAR(back.y(), increment.y(), 1e-9);
    ASSERT_NEAR(NormalizeAngle(back.theta() - increment.theta()), 0.0, 1e-9);
  }
}

TEST(RotTransRotTest, BackwardMotionHasNegativeTranslation) {
  const RotTransRot m = RotTransRot::FromIncrement(Pose2(-1.0, 0.0, 0.2));
  EXPECT_NEAR(m.trans_m, -1.0, 1e-12);
  EXPECT_NEAR(m.rot1_rad, 0.0, 1e-12);
  EXPECT_NEAR(m.rot2_rad, 0.2, 1e-12);
}

TEST(RotTransRotTest, ZeroNoiseReturnsTheIncrement) {
  RandomEngine rng(1);
  const Pose2 increment(0.3, 0.05, 0.1);
  ExpectPoseNear(SampleRotTransRot(increment, RotTransRotNoise{0, 0, 0, 0, 0, 0}, rng), increment,
                 1e-12);
}

// Sample moments match Table 5.6's variances.
TEST(RotTransRotTest, SampleMomentsMatchTheAlphaModel) {
  RotTransRotNoise noise;
  noise.alpha1 = 0.1;
  noise.alpha2 = 0.02;
  noise.alpha3 = 0.05;
  noise.alpha4 = 0.01;
  const Pose2 increment = RotTransRot{0.2, 1.0, -0.1}.ToIncrement();
  RandomEngine rng(42);
  const int n = 200000;
  double sum_trans = 0.0, sum_trans2 = 0.0, sum_rot1 = 0.0, sum_rot12 = 0.0;
  for (int i = 0; i < n; ++i) {
    const RotTransRot s = RotTransRot::FromIncrement(SampleRotTransRot(increment, noise, rng));
    sum_trans += s.trans_m;
    sum_trans2 += s.trans_m * s.trans_m;
    sum_rot1 += s.rot1_rad;
    sum_rot12 += s.rot1_rad * s.rot1_rad;
  }
  const double mean_trans = sum_trans / n;
  const double var_trans = sum_trans2 / n - mean_trans * mean_trans;
  const double mean_rot1 = sum_rot1 / n;
  const double var_rot1 = sum_rot12 / n - mean_rot1 * mean_rot1;
  EXPECT_NEAR(mean_trans, 1.0, 0.005);
  EXPECT_NEAR(var_trans, 0.05 * 1.0 + 0.01 * (0.04 + 0.01), 0.003);
  EXPECT_NEAR(mean_rot1, 0.2, 0.005);
  EXPECT_NEAR(var_rot1, 0.1 * 0.04 + 0.02 * 1.0, 0.001);
}

TEST(RotTransRotTest, SameSeedSameSamples) {
  RandomEngine a(5), b(5);
  const Pose2 increment(0.5, 0.0, 0.3);
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(SampleRotTransRot(increment, {}, a), SampleRotTransRot(increment, {}, b));
  }
}

TEST(RotTransRotTest, ValidateNamesFieldValueAndRule) {
  RotTransRotNoise noise;
  noise.alpha3 = -1.0;
  EXPECT_THAT(noise.Validate(), testing::ElementsAre("alpha3 = -1; must be >= 0"));
}

TEST(GaussianTest, StandardNormalHasUnitMoments) {
  RandomEngine rng(3);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = StandardNormal(rng);
    sum += x;
    sum2 += x * x;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.01);
}

}  // namespace
}  // namespace slamrig::slam
