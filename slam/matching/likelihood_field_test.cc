#include "slam/matching/likelihood_field.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

TEST(LikelihoodFieldTest, ValueFollowsDistanceToTheNearestWall) {
  OccupancyGridOptions grid_options;
  grid_options.resolution_m = 0.05;
  OccupancyGrid grid(grid_options);
  grid.EnsureContains(Eigen::AlignedBox2d(Eigen::Vector2d(0, 0), Eigen::Vector2d(2, 2)));
  const Eigen::Array2i wall_a = grid.WorldToCell({1.0, 1.0});
  const Eigen::Array2i wall_b = grid.WorldToCell({1.3, 1.0});
  grid.Set(wall_a, 2.0f);
  grid.Set(wall_b, 2.0f);
  grid.Set(grid.WorldToCell({0.5, 0.5}), -2.0f);  // free cell: not a wall

  LikelihoodFieldOptions options;
  options.sigma_m = 0.05;
  LikelihoodField field(options);
  field.Update(grid, Eigen::AlignedBox2d(Eigen::Vector2d(0.2, 0.2), Eigen::Vector2d(1.8, 1.8)));
  const GridView view = field.view();
  for (double x = 0.25; x < 1.75; x += 0.05) {
    for (double y = 0.25; y < 1.75; y += 0.05) {
      const Eigen::Array2i cell = grid.WorldToCell({x, y});
      const Eigen::Vector2d c = grid.CellCenter(cell);
      const double d =
          std::min((c - grid.CellCenter(wall_a)).norm(), (c - grid.CellCenter(wall_b)).norm());
      const int vx = static_cast<int>(std::floor((c.x() - view.origin.x()) / view.resolution));
      const int vy = static_cast<int>(std::floor((c.y() - view.origin.y()) / view.resolution));
      ASSERT_NEAR(view.At(vx, vy), field.Score(d), 1e-5) << x << " " << y;
    }
  }
  EXPECT_NEAR(field.Score(0.0), std::log(1.0 / 0.1), 1e-12);
  EXPECT_EQ(field.Score(1.0), 0.0);
}

}  // namespace
}  // namespace slamrig::slam
