#include "slam/eval/nees.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <random>

#include "slam/eval/chi_square.h"

namespace slamrig::slam {
namespace {

// Three calls of `draw` as (x, y, z), z drawn first: sequenced (the arguments of one call are
// drawn in the compiler's order), in the order the cases here were generated with.
template <typename Draw>
Eigen::Vector3d Draw3(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  return {draw(), y, z};
}

// Table values of the chi-square distribution (Abramowitz and Stegun, Table 26.8).
TEST(NeesTest, ChiSquareQuantileAndAneesBoundsMatchTables) {
  EXPECT_NEAR(ChiSquareQuantile(0.975, 3), 9.348, 0.001);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 3), 0.2158, 0.001);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 60), 40.482, 0.001);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 60), 83.298, 0.001);
  const NeesBounds b = AneesBounds(3, 20);
  EXPECT_NEAR(b.lower, 40.482 / 20, 0.005);
  EXPECT_NEAR(b.upper, 83.298 / 20, 0.005);
  const NeesBounds two = AneesBounds(2, 1);  // chi2_2 is exponential: -2 ln(1 - p)
  EXPECT_NEAR(two.lower, -2.0 * std::log(0.975), 1e-6);
  EXPECT_NEAR(two.upper, -2.0 * std::log(0.025), 1e-6);
}

// Against tables of the F distribution (Abramowitz and Stegun, Table 26.9).
TEST(NeesTest, FQuantileMatchesTables) {
  EXPECT_NEAR(FQuantile(0.99, 40, 20), 2.69, 0.05);
  EXPECT_NEAR(FQuantile(0.99, 10, 10), 4.85, 0.1);
  EXPECT_NEAR(FQuantile(0.95, 5, 10), 3.33, 0.05);
  EXPECT_NEAR(FQuantile(0.95, 60, 60), 1.53, 0.03);
}

// Errors drawn from the covariance itself have NEES with mean = dimension, and the angle is
// wrapped.
TEST(NeesTest, NeesOfErrorsDrawnFromTheCovarianceAveragesTheDimension) {
  Eigen::Matrix3d p;
  p << 0.04, 0.01, 0.002, 0.01, 0.09, -0.001, 0.002, -0.001, 0.01;
  const Eigen::Matrix3d l = p.llt().matrixL();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  double sum = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d e = l * Draw3([&] { return normal(rng); });
    const Pose2 estimate(1.0, 2.0, 3.1);
    sum += PoseNees(Pose2(1.0 + e.x(), 2.0 + e.y(), 3.1 + e.z()), estimate, p);
  }
  EXPECT_NEAR(sum / n, 3.0, 0.1);
}

// e^T P^-1 e with the explicit inverse, over random poses and covariances.
TEST(NeesTest, PoseNeesEqualsTheQuadraticFormWithTheInverse) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int k = 0; k < 200; ++k) {
    Eigen::Matrix3d a = Eigen::Matrix3d::NullaryExpr([&] { return u(rng); });
    const Eigen::Matrix3d p = a * a.transpose() + 0.1 * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d t = Draw3([&] { return u(rng); }), s = Draw3([&] { return u(rng); });
    const Pose2 truth(t.x(), t.y(), t.z()), estimate(s.x(), s.y(), s.z());
    double yaw = truth.theta() - estimate.theta();
    while (yaw > M_PI) yaw -= 2 * M_PI;
    while (yaw < -M_PI) yaw += 2 * M_PI;
    const Eigen::Vector3d e(truth.x() - estimate.x(), truth.y() - estimate.y(), yaw);
    const double expected = e.transpose() * p.inverse() * e;
    EXPECT_NEAR(PoseNees(truth, estimate, p), expected, 1e-9 * std::max(1.0, expected)) << k;
  }
  EXPECT_TRUE(std::isinf(PoseNees(Pose2(), Pose2(1, 0, 0), Eigen::Matrix3d::Zero())));
}

// A covariance turned by a quarter turn swaps its x and y variances; turning back restores it.
TEST(NeesTest, RotateCovarianceTurnsTheAxes) {
  const Eigen::Matrix3d p = Eigen::Vector3d(4.0, 1.0, 0.5).asDiagonal();
  const Eigen::Matrix3d q = RotateCovariance(p, M_PI / 2);
  EXPECT_NEAR(q(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(q(1, 1), 4.0, 1e-12);
  EXPECT_NEAR(q(2, 2), 0.5, 1e-12);
  EXPECT_NEAR(q(0, 1), 0.0, 1e-12);
  Eigen::Matrix3d r;
  r << 0.3, 0.1, 0.02, 0.1, 0.2, -0.01, 0.02, -0.01, 0.05;
  EXPECT_TRUE(RotateCovariance(RotateCovariance(r, 0.7), -0.7).isApprox(r, 1e-12));
}

// The series pairs poses by time, turns each covariance into the reference's frame and leaves
// out singular ones: against a hand computation on three poses.
TEST(NeesTest, SeriesPairsByTimeAndTurnsTheCovariance) {
  Trajectory estimate, reference;
  for (int i = 0; i < 3; ++i) {
    estimate.Append(Time::FromSeconds(i), Pose2(i, 0.0, 0.0));
    reference.Append(Time::FromSeconds(i), Pose2(i + 0.2 * i, 0.0, 0.0));  // x error 0.2 i
  }
  // In the estimator's frame, turned by 90 degrees from the reference's: its y is the
  // reference's x.
  const Eigen::Matrix3d p = Eigen::Vector3d(1.0, 0.01, 0.1).asDiagonal();
  const std::vector<Eigen::Matrix3d> covariances = {Eigen::Matrix3d::Zero(), p, p};
  const NeesSeries s = PoseNeesSeries(estimate, covariances, M_PI / 2, reference);
  ASSERT_EQ(s.nees.size(), 2u);  // the singular first one left out
  EXPECT_EQ(s.time_s, (std::vector<double>{1.0, 2.0}));
  EXPECT_NEAR(s.nees[0], 0.2 * 0.2 / 0.01, 1e-9);
  EXPECT_NEAR(s.nees[1], 0.4 * 0.4 / 0.01, 1e-9);
  // Not one covariance per pose: nothing.
  EXPECT_TRUE(PoseNeesSeries(estimate, {p}, 0.0, reference).nees.empty());
}

}  // namespace
}  // namespace slamrig::slam
