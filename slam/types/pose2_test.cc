#include "slam/types/pose2.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace slamrig {
namespace {

constexpr int kNumTrials = 10000;
constexpr double kPi = std::numbers::pi;

Pose2 RandomPose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> xy(-100.0, 100.0);
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  // Sequenced draws, the last coordinate first (the order these cases were generated in).
  const double theta = angle(rng), y = xy(rng), x = xy(rng);
  return Pose2(x, y, theta);
}

void ExpectPoseNear(const Pose2& a, const Pose2& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol);
  EXPECT_NEAR(a.y(), b.y(), tol);
  EXPECT_NEAR(NormalizeAngle(a.theta() - b.theta()), 0.0, tol);
}

TEST(NormalizeAngleTest, LandsInHalfOpenInterval) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> angle(-1000.0, 1000.0);
  for (int i = 0; i < kNumTrials; ++i) {
    const double a = angle(rng);
    const double n = NormalizeAngle(a);
    ASSERT_GT(n, -kPi) << a;
    ASSERT_LE(n, kPi) << a;
    // Same direction as the input.
    ASSERT_NEAR(std::cos(n), std::cos(a), 1e-9);
    ASSERT_NEAR(std::sin(n), std::sin(a), 1e-9);
  }
}

TEST(NormalizeAngleTest, BoundaryValues) {
  EXPECT_DOUBLE_EQ(NormalizeAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(NormalizeAngle(-kPi), kPi);
  EXPECT_DOUBLE_EQ(NormalizeAngle(3 * kPi), kPi);
  EXPECT_DOUBLE_EQ(NormalizeAngle(0.0), 0.0);
  EXPECT_NEAR(NormalizeAngle(2 * kPi + 0.5), 0.5, 1e-12);
}

TEST(Pose2Test, ComposeWithInverseIsIdentity) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < kNumTrials; ++i) {
    const Pose2 p = RandomPose(rng);
    ExpectPoseNear(p * p.Inverse(), Pose2(), 1e-9);
    ExpectPoseNear(p.Inverse() * p, Pose2(), 1e-9);
  }
}

TEST(Pose2Test, BetweenRoundTrips) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < kNumTrials; ++i) {
    const Pose2 a = RandomPose(rng);
    const Pose2 b = RandomPose(rng);
    ExpectPoseNear(a * a.Between(b), b, 1e-9);
  }
}

TEST(Pose2Test, CompositionIsAssociative) {
  std::mt19937_64 rng(4);
  for (int i = 0; i < kNumTrials; ++i) {
    const Pose2 a = RandomPose(rng), b = RandomPose(rng), c = RandomPose(rng);
    ExpectPoseNear((a * b) * c, a * (b * c), 1e-8);
  }
}

TEST(Pose2Test, TransformPointMatchesComposition) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < kNumTrials; ++i) {
    const Pose2 a = RandomPose(rng), b = RandomPose(rng);
    const Eigen::Vector2d p = (a * b).translation();
    const Eigen::Vector2d q = a * b.translation();
    ASSERT_NEAR((p - q).norm(), 0.0, 1e-9);
  }
}

TEST(Pose2Test, HandComputedComposition) {
  // Robot at (1, 2) facing +y; laser 0.5 m ahead of it: the laser is at (1, 2.5) facing +y.
  const Pose2 world_from_robot(1.0, 2.0, kPi / 2);
  const Pose2 robot_from_laser(0.5, 0.0, 0.0);
  ExpectPoseNear(world_from_robot * robot_from_laser, Pose2(1.0, 2.5, kPi / 2), 1e-12);
  const Eigen::Vector2d hit = world_from_robot * Eigen::Vector2d(1.0, 0.0);
  EXPECT_NEAR(hit.x(), 1.0, 1e-12);
  EXPECT_NEAR(hit.y(), 3.0, 1e-12);
}

TEST(Pose2Test, RotationMatchesPointTransform) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> xy(-10.0, 10.0);
  for (int i = 0; i < kNumTrials; ++i) {
    const Pose2 a = RandomPose(rng);
    const double y = xy(rng);  // drawn first, as in RandomPose
    const Eigen::Vector2d p(xy(rng), y);
    ASSERT_NEAR((a * p - (a.Rotation() * p + a.translation())).norm(), 0.0, 1e-9);
    ASSERT_NEAR((a.Rotation().transpose() * a.Rotation() - Eigen::Matrix2d::Identity()).norm(), 0.0,
                1e-12);
  }
  // A quarter turn maps +x onto +y.
  const Eigen::Vector2d y = RotationMatrix(kPi / 2) * Eigen::Vector2d(1.0, 0.0);
  EXPECT_NEAR(y.x(), 0.0, 1e-15);
  EXPECT_NEAR(y.y(), 1.0, 1e-15);
}

TEST(Pose2Test, RotateCovarianceTurnsTheTranslationBlockOnly) {
  // Variance 4 along x and 1 along y, turned by a quarter turn: 1 along x and 4 along y, and the
  // x-yaw correlation becomes a y-yaw one.
  Eigen::Matrix3d p;
  p << 4.0, 0.0, 0.5, 0.0, 1.0, 0.0, 0.5, 0.0, 0.25;
  const Eigen::Matrix3d q = RotateCovariance(p, kPi / 2);
  Eigen::Matrix3d expected;
  expected << 1.0, 0.0, 0.0, 0.0, 4.0, 0.5, 0.0, 0.5, 0.25;
  EXPECT_NEAR((q - expected).norm(), 0.0, 1e-12);
  // Turning there and back is the identity.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  for (int i = 0; i < 1000; ++i) {
    const double a = angle(rng);
    ASSERT_NEAR((RotateCovariance(RotateCovariance(p, a), -a) - p).norm(), 0.0, 1e-12);
  }
}

}  // namespace
}  // namespace slamrig
