#include "slam/graph/edge_error.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace slamrig::slam {
namespace {

// Three draws of `u` as (x, y, z), z drawn first: sequenced (the arguments of one call are drawn
// in the compiler's order), in the order the cases here were generated with.
Eigen::Vector3d Draw3(std::mt19937_64& rng, std::uniform_real_distribution<double>& u) {
  const double z = u(rng);
  const double y = u(rng);
  return {u(rng), y, z};
}

Pose2 RandomPose(std::mt19937_64& rng, std::uniform_real_distribution<double>& u) {
  const Eigen::Vector3d v = Draw3(rng, u);
  return Pose2(v.x(), v.y(), v.z());
}

constexpr double kPi = std::numbers::pi;

TEST(EdgeErrorTest, MatchesAHandComputation) {
  // Xi at (1, 2) facing +y, Xj at (0, 2) facing -x: Xi^-1 * Xj = (0, 1, pi/2). With Z = (1, 0, 0)
  // the error is (-1, 1, pi/2).
  const EdgeErrorResult r = EvaluateEdgeError({1.0, 2.0, kPi / 2}, {0.0, 2.0, kPi}, Pose2(1, 0, 0));
  EXPECT_NEAR(r.error.x(), -1.0, 1e-12);
  EXPECT_NEAR(r.error.y(), 1.0, 1e-12);
  EXPECT_NEAR(r.error.z(), kPi / 2, 1e-12);

  // Z rotated too: Z = (0, 1, pi/2) is exactly Xi^-1 * Xj, so the error vanishes.
  const EdgeErrorResult zero =
      EvaluateEdgeError({1.0, 2.0, kPi / 2}, {0.0, 2.0, kPi}, Pose2(0, 1, kPi / 2));
  EXPECT_NEAR(zero.error.norm(), 0.0, 1e-12);
}

TEST(EdgeErrorTest, AngleErrorIsWrapped) {
  // theta_j - theta_i - theta_z = 3.0 - (-3.0) - 0 = 6.0 rad, i.e. 6 - 2 pi.
  const EdgeErrorResult r = EvaluateEdgeError({0, 0, -3.0}, {0, 0, 3.0}, Pose2());
  EXPECT_NEAR(r.error.z(), 6.0 - 2 * kPi, 1e-12);
}

TEST(EdgeErrorTest, Chi2OfATinyGraphIsTheSumOfWeightedSquares) {
  PoseGraph graph;
  graph.AddVertex(0, Pose2(1.0, 2.0, kPi / 2));
  graph.AddVertex(1, Pose2(0.0, 2.0, kPi));
  graph.AddVertex(2, Pose2(0.0, 0.0, 0.0));
  Eigen::Matrix3d omega_a = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
  Eigen::Matrix3d omega_b;
  omega_b << 4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0;
  graph.AddEdge({.from = 0, .to = 1, .measurement = Pose2(1, 0, 0), .information = omega_a});
  // Xi = X1 = (0, 2, pi), Xj = X2 = origin: Xi^-1 * Xj = (0, 2, pi) (angle wrapped);
  // Z = (0, 0, pi) turns the translation by -pi: e = (0, -2, 0).
  graph.AddEdge({.from = 1, .to = 2, .measurement = Pose2(0, 0, kPi), .information = omega_b});
  // First edge: e = (-1, 1, pi/2), chi2 = 1 + 2 + 3 pi^2 / 4. Second: e^T Omega e = 3 * 2^2.
  const double expected = 1.0 + 2.0 + 3.0 * kPi * kPi / 4.0 + 12.0;
  EXPECT_NEAR(Chi2(graph), expected, 1e-9);
  EXPECT_NEAR(EdgeError(graph, graph.edges()[1]).y(), -2.0, 1e-12);
}

TEST(EdgeErrorTest, AgreesWithPose2CompositionOnRandomPoses) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Pose2 xi = RandomPose(rng, u), xj = RandomPose(rng, u), z = RandomPose(rng, u);
    const Pose2 expected = z.Inverse() * (xi.Inverse() * xj);
    const Eigen::Vector3d e =
        EvaluateEdgeError({xi.x(), xi.y(), xi.theta()}, {xj.x(), xj.y(), xj.theta()}, z).error;
    EXPECT_NEAR(e.x(), expected.x(), 1e-9);
    EXPECT_NEAR(e.y(), expected.y(), 1e-9);
    EXPECT_NEAR(NormalizeAngle(e.z() - expected.theta()), 0.0, 1e-9);
  }
}

TEST(EdgeErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  const double h = 1e-6;
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Vector3d xi = Draw3(rng, u), xj = Draw3(rng, u);
    const Pose2 z = RandomPose(rng, u);
    const EdgeErrorResult r = EvaluateEdgeError(xi, xj, z);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(k);
      Eigen::Vector3d di =
          EvaluateEdgeError(xi + d, xj, z).error - EvaluateEdgeError(xi - d, xj, z).error;
      Eigen::Vector3d dj =
          EvaluateEdgeError(xi, xj + d, z).error - EvaluateEdgeError(xi, xj - d, z).error;
      di.z() = NormalizeAngle(di.z());
      dj.z() = NormalizeAngle(dj.z());
      EXPECT_LT((di / (2 * h) - r.d_error_d_xi.col(k)).norm(), 1e-6) << trial << " " << k;
      EXPECT_LT((dj / (2 * h) - r.d_error_d_xj.col(k)).norm(), 1e-6) << trial << " " << k;
    }
  }
}

}  // namespace
}  // namespace slamrig::slam
