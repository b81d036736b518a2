#include "slam/matching/point_kd_tree.h"

#include <gtest/gtest.h>

#include <limits>

#include "slam/odometry/gaussian.h"

namespace slamrig::slam {
namespace {

// The nearest point within a bound, against a scan of every point, on random clouds and queries
// near them and far away.
TEST(PointKdTreeTest, NearestWithinABoundIsTheClosestPointWithinIt) {
  RandomEngine rng(41);
  int within = 0, beyond = 0;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Eigen::Vector2d> points;
    const int n = 1 + static_cast<int>(300 * Uniform01(rng));
    for (int p = 0; p < n; ++p) {
      const double x = 10.0 * Uniform01(rng);
      points.emplace_back(x, 10.0 * Uniform01(rng));
    }
    const PointKdTree tree(points);
    for (int q = 0; q < 40; ++q) {
      const double x = 14.0 * Uniform01(rng) - 2.0;
      const Eigen::Vector2d query(x, 14.0 * Uniform01(rng) - 2.0);
      const double u = Uniform01(rng);
      const double bound =
          q % 4 == 0 ? std::numeric_limits<double>::infinity() : 0.5 * u * Uniform01(rng);
      std::size_t best = 0;
      for (std::size_t p = 1; p < points.size(); ++p) {
        if ((points[p] - query).squaredNorm() < (points[best] - query).squaredNorm()) best = p;
      }
      const double best_d2 = (points[best] - query).squaredNorm();
      std::uint32_t index = 0;
      double d2 = -1.0;
      const bool found = tree.Nearest(query, &index, &d2, bound);
      ASSERT_EQ(found, best_d2 <= bound) << trial << " " << q;
      if (!found) {
        ++beyond;
        continue;
      }
      ++within;
      EXPECT_EQ(index, best);
      EXPECT_EQ(d2, best_d2);
      // A bound of exactly that distance still holds it.
      EXPECT_TRUE(tree.Nearest(query, &index, &d2, best_d2));
      EXPECT_EQ(index, best);
    }
  }
  EXPECT_GT(within, 200);
  EXPECT_GT(beyond, 200);
  const PointKdTree empty(std::vector<Eigen::Vector2d>{});
  std::uint32_t index = 0;
  double d2 = 0.0;
  EXPECT_FALSE(empty.Nearest(Eigen::Vector2d::Zero(), &index, &d2));
}

}  // namespace
}  // namespace slamrig::slam
