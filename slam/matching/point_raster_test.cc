#include "slam/matching/point_raster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "slam/odometry/gaussian.h"

namespace slamrig::slam {
namespace {

// The raster as point_raster.h defines it, computed point by point: each point blurs the cells
// within 3 sigma of its own cell (in cells, a square) and a cell keeps the largest blur.
std::vector<float> BlurredByEachPoint(const std::vector<Eigen::Vector2d>& points,
                                      const GridView& view, double sigma_m) {
  const int reach = static_cast<int>(std::ceil(3.0 * sigma_m / view.resolution));
  std::vector<float> values(static_cast<std::size_t>(view.width) * view.height, 0.0f);
  for (const Eigen::Vector2d& p : points) {
    const int cx = static_cast<int>(std::floor((p.x() - view.origin.x()) / view.resolution));
    const int cy = static_cast<int>(std::floor((p.y() - view.origin.y()) / view.resolution));
    for (int y = cy - reach; y <= cy + reach; ++y) {
      for (int x = cx - reach; x <= cx + reach; ++x) {
        if (x < 0 || y < 0 || x >= view.width || y >= view.height) continue;
        const Eigen::Vector2d centre =
            view.origin + view.resolution * Eigen::Vector2d(x + 0.5, y + 0.5);
        const auto blur =
            static_cast<float>(std::exp(-(centre - p).squaredNorm() / (2.0 * sigma_m * sigma_m)));
        float& cell = values[static_cast<std::size_t>(y) * view.width + x];
        cell = std::max(cell, blur);
      }
    }
  }
  return values;
}

TEST(PointRasterTest, EachCellHoldsTheLargestBlurOfThePointsWithinReach) {
  RandomEngine rng(31);
  for (int trial = 0; trial < 30; ++trial) {
    std::vector<Eigen::Vector2d> points;
    const int n = 1 + static_cast<int>(200 * Uniform01(rng));
    const double spread = 0.2 + 5.0 * Uniform01(rng);
    for (int p = 0; p < n; ++p) {
      const double x = spread * (2.0 * Uniform01(rng) - 1.0);
      points.emplace_back(x, spread * (2.0 * Uniform01(rng) - 1.0));
    }
    const double resolution = 0.02 + 0.1 * Uniform01(rng);
    const double sigma = resolution * (0.3 + 3.0 * Uniform01(rng));
    const PointRaster raster = RasterOf(points, resolution, sigma);
    ASSERT_EQ(raster.view.values, raster.values.data());
    ASSERT_EQ(raster.values.size(),
              static_cast<std::size_t>(raster.view.width) * raster.view.height);
    // Every point lies a whole reach inside the raster: its blur is never cut.
    const int reach = static_cast<int>(std::ceil(3.0 * sigma / resolution));
    for (const Eigen::Vector2d& p : points) {
      const Eigen::Vector2d cell = (p - raster.view.origin) / resolution;
      EXPECT_GE(cell.minCoeff(), reach);
      EXPECT_LT(cell.x(), raster.view.width - reach);
      EXPECT_LT(cell.y(), raster.view.height - reach);
    }
    EXPECT_EQ(raster.values, BlurredByEachPoint(points, raster.view, sigma)) << trial;
  }
}

TEST(PointRasterTest, ScoreIsTheMeanValueUnderThePlacedPoints) {
  const std::vector<Eigen::Vector2d> points{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
  const PointRaster raster = RasterOf(points, 0.1, 0.05);
  // At the identity each point reads its own cell, whose nearest point is itself (the others are
  // 1 m away): exp(-d^2 / (2 sigma^2)), d from the point to that cell's centre.
  double expected = 0.0;
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d cell = ((p - raster.view.origin) / 0.1).array().floor();
    const Eigen::Vector2d centre = raster.view.origin + 0.1 * (cell + Eigen::Vector2d(0.5, 0.5));
    expected += static_cast<float>(std::exp(-(centre - p).squaredNorm() / (2.0 * 0.05 * 0.05)));
  }
  EXPECT_DOUBLE_EQ(RasterScore(raster, points, Pose2()), expected / 3.0);
  // Moved far away, every point reads outside: 0.
  EXPECT_EQ(RasterScore(raster, points, Pose2(100.0, 0.0, 0.0)), 0.0);
  EXPECT_EQ(RasterScore(raster, {}, Pose2()), 0.0);
}

TEST(PointRasterTest, ThinningKeepsTheFirstPointOfEachVoxel) {
  const std::vector<Eigen::Vector2d> points{{0.01, 0.01},  {0.09, 0.02}, {0.11, 0.01},
                                            {-0.01, 0.01}, {0.05, 0.05}, {0.12, 0.05}};
  const std::vector<Eigen::Vector2d> kept = Thinned(points, 0.1);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0], points[0]);
  EXPECT_EQ(kept[1], points[2]);
  EXPECT_EQ(kept[2], points[3]);
}

}  // namespace
}  // namespace slamrig::slam
