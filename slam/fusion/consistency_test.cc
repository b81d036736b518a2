#include "slam/fusion/consistency.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

namespace slamrig::slam {
namespace {

// Table values of the chi-square distribution (Abramowitz and Stegun, Table 26.8).
TEST(ConsistencyTest, ChiSquareQuantileMatchesTables) {
  EXPECT_NEAR(ChiSquareQuantile(0.975, 3), 9.348, 0.001);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 3), 0.2158, 0.001);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 60), 40.482, 0.001);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 60), 83.298, 0.001);
  const NeesBounds b = AneesBounds(3, 20);
  EXPECT_NEAR(b.lower, 40.482 / 20, 0.005);
  EXPECT_NEAR(b.upper, 83.298 / 20, 0.005);
}

// Errors drawn from the covariance itself have NEES with mean = dimension, and the angle is
// wrapped.
TEST(ConsistencyTest, NeesOfErrorsDrawnFromTheCovarianceAveragesTheDimension) {
  Eigen::Matrix3d p;
  p << 0.04, 0.01, 0.002, 0.01, 0.09, -0.001, 0.002, -0.001, 0.01;
  const Eigen::Matrix3d l = p.llt().matrixL();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  double sum = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d e = l * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const Pose2 estimate(1.0, 2.0, 3.1);
    sum += PoseNees(Pose2(1.0 + e.x(), 2.0 + e.y(), 3.1 + e.z()), estimate, p);
  }
  EXPECT_NEAR(sum / n, 3.0, 0.1);
}

// Against tables of the F distribution (Abramowitz and Stegun, Table 26.9).
TEST(ConsistencyTest, FQuantileMatchesTables) {
  EXPECT_NEAR(FQuantile(0.99, 40, 20), 2.69, 0.05);
  EXPECT_NEAR(FQuantile(0.99, 10, 10), 4.85, 0.1);
  EXPECT_NEAR(FQuantile(0.95, 5, 10), 3.33, 0.05);
  EXPECT_NEAR(FQuantile(0.95, 60, 60), 1.53, 0.03);
}

}  // namespace
}  // namespace slamrig::slam
