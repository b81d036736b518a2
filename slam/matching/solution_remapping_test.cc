#include "slam/matching/solution_remapping.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace slamrig::slam {
namespace {

// A corridor 2.4 m wide seen from its middle, points every 5 cm in beam order: the right wall
// from far behind to far ahead, then the left wall back.
std::vector<Eigen::Vector2d> Corridor(double half_length_m) {
  std::vector<Eigen::Vector2d> points;
  for (double x = -half_length_m; x <= half_length_m; x += 0.05) points.emplace_back(x, -1.2);
  for (double x = half_length_m; x >= -half_length_m; x -= 0.05) points.emplace_back(x, 1.2);
  return points;
}

TEST(SolutionRemappingTest, ACorridorLeavesItsAxisUnconstrained) {
  const std::vector<Eigen::Vector2d> points = Corridor(8.0);
  const MatchConstraints c =
      DecomposeInformation(ScanInformation(points, SurfaceNormals(points, 0.3)));
  EXPECT_EQ(c.WeakCount(0.05), 1);
  EXPECT_LT(c.eigenvalues.x(), 1e-6 * c.eigenvalues.y());
  EXPECT_NEAR(std::abs(c.eigenvectors.col(0).x()), 1.0, 1e-6);  // the weak one is the axis
}

TEST(SolutionRemappingTest, AnEndWallConstrainsTheAxis) {
  std::vector<Eigen::Vector2d> points = Corridor(8.0);
  // Close the corridor 3 m ahead: points on x = 3 between the walls, inserted in beam order.
  std::vector<Eigen::Vector2d> closed;
  for (const Eigen::Vector2d& p : points) {
    if (p.x() <= 3.0) closed.push_back(p);
    if (p.y() < 0 && std::abs(p.x() - 3.0) < 0.025) {
      for (double y = -1.15; y < 1.2; y += 0.05) closed.emplace_back(3.0, y);
    }
  }
  const MatchConstraints c =
      DecomposeInformation(ScanInformation(closed, SurfaceNormals(closed, 0.3)));
  EXPECT_EQ(c.WeakCount(0.05), 0);
}

// The information is invariant to where the yaw's coupling puts it: a rotated scan gives the
// same eigenvalues, and its weak direction turns with it.
TEST(SolutionRemappingTest, InformationTurnsWithTheScan) {
  const double angle = 0.7;
  const Pose2 rotation(0.0, 0.0, angle);
  std::vector<Eigen::Vector2d> turned;
  for (const Eigen::Vector2d& p : Corridor(8.0)) turned.push_back(rotation * p);
  const MatchConstraints c =
      DecomposeInformation(ScanInformation(turned, SurfaceNormals(turned, 0.3)));
  EXPECT_EQ(c.WeakCount(0.05), 1);
  const Eigen::Vector2d weak = c.eigenvectors.col(0);
  EXPECT_NEAR(std::abs(weak.dot(Eigen::Vector2d(std::cos(angle), std::sin(angle)))), 1.0, 1e-6);
}

// Random corrections: the remapped pose keeps the strong component (robot frame) and the
// prediction's weak one, and the match's yaw.
TEST(SolutionRemappingTest, RemappingKeepsOnlyTheConstrainedPartOfTheCorrection) {
  MatchConstraints c;
  c.eigenvalues = Eigen::Vector2d(1.0, 100.0);  // x (robot frame) weak, y strong
  c.eigenvectors = Eigen::Matrix2d::Identity();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    // Sequenced draws, the last coordinate first (the order these cases were generated in).
    const double theta = 3 * u(rng), y = 5 * u(rng), x = 5 * u(rng);
    const Pose2 predicted(x, y, theta);
    const double dtheta = u(rng), dy = u(rng), dx = u(rng);
    const Pose2 matched(predicted.x() + dx, predicted.y() + dy, predicted.theta() + dtheta);
    const Pose2 remapped = RemapAlongWeakDirections(predicted, matched, c, 0.05);
    const Pose2 seen = predicted.Inverse() * Pose2(remapped.x(), remapped.y(), predicted.theta());
    const Pose2 wanted = predicted.Inverse() * Pose2(matched.x(), matched.y(), predicted.theta());
    EXPECT_NEAR(seen.x(), 0.0, 1e-9);
    EXPECT_NEAR(seen.y(), wanted.y(), 1e-9);
    EXPECT_DOUBLE_EQ(remapped.theta(), matched.theta());
    // Nothing weak: the match itself.
    const Pose2 all = RemapAlongWeakDirections(predicted, matched, c, 0.001);
    EXPECT_NEAR(all.x(), matched.x(), 1e-9);
    EXPECT_NEAR(all.y(), matched.y(), 1e-9);
  }
}

TEST(SolutionRemappingTest, DropsGrazingPointsOnly) {
  // A wall at y = 1 seen from the origin: the incidence angle is atan(x / 1).
  std::vector<Eigen::Vector2d> wall;
  for (double x = -5.0; x <= 5.0; x += 0.05) wall.emplace_back(x, 1.0);
  const SelectedPoints kept = DropGrazingPoints(wall, SurfaceNormals(wall, 0.3), 1.0);
  ASSERT_FALSE(kept.points.empty());
  for (const Eigen::Vector2d& p : kept.points) EXPECT_LE(std::abs(p.x()), std::tan(1.0) + 0.05);
  EXPECT_GT(kept.points.size(), 60u);  // |x| <= 1.56 m: about 62 points
  EXPECT_EQ(DropGrazingPoints(wall, SurfaceNormals(wall, 0.3), 1.5707963267948966).points.size(),
            wall.size());
}

TEST(SolutionRemappingTest, IsolatedPointsHaveNoNormal) {
  const std::vector<Eigen::Vector2d> points = {{1, 0}, {5, 5}, {-3, 2}};
  for (const Eigen::Vector2d& n : SurfaceNormals(points, 0.3)) EXPECT_TRUE(n.isZero());
  EXPECT_TRUE(ScanInformation(points, SurfaceNormals(points, 0.3)).isZero());
}

}  // namespace
}  // namespace slamrig::slam
