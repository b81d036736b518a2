#include "slam/matching/likelihood_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

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

// The whole grid as an Update region: the centres of its corner cells.
Eigen::AlignedBox2d WholeGrid(const OccupancyGrid& grid) {
  return Eigen::AlignedBox2d(grid.CellCenter({0, 0}),
                             grid.CellCenter({grid.width() - 1, grid.height() - 1}));
}

// Bit-for-bit equality of two rasters over the same cells (NaN-safe, -0 != +0).
bool SameBits(const GridView& a, const GridView& b) {
  if (a.width != b.width || a.height != b.height || a.origin != b.origin) return false;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const float va = a.At(x, y), vb = b.At(x, y);
      if (std::memcmp(&va, &vb, sizeof(float)) != 0) return false;
    }
  }
  return true;
}

// A scan of `beams` random ranges over 360 degrees (some no-returns, some short).
LaserScan RandomScan(std::mt19937& rng, int beams) {
  LaserScan scan;
  scan.angle_min_rad = -3.14159;
  scan.angle_increment_rad = 2 * 3.14159 / beams;
  scan.range_min_m = 0.1;
  scan.range_max_m = 4.0;
  std::uniform_real_distribution<float> range(0.05f, 4.5f);
  for (int i = 0; i < beams; ++i) scan.ranges_m.push_back(range(rng));
  return scan;
}

// A 5 cm grid that grows by `grow_margin_m`, and the field of sigma 0.06 m at `threshold`, as
// the follow properties below use them.
OccupancyGridOptions GrowingGrid(double grow_margin_m) {
  OccupancyGridOptions o;
  o.resolution_m = 0.05;
  o.grow_margin_m = grow_margin_m;
  return o;
}
LikelihoodFieldOptions FieldAt(float threshold) {
  LikelihoodFieldOptions o;
  o.sigma_m = 0.06;
  o.occupied_threshold = threshold;
  return o;
}

// Property: after random scans (the grid grows), random walls set and erased, the followed
// field equals a whole recompute bit for bit, everywhere and in every window; for thresholds
// above and below 0 (below 0 the unknown cells the grid grows into are walls).
TEST(LikelihoodFieldTest, FollowEqualsAWholeRecomputeBitForBit) {
  for (const float threshold : {0.0f, 0.5f, -0.2f}) {
    std::mt19937 rng(7);
    const OccupancyGridOptions grid_options = GrowingGrid(0.3);
    OccupancyGrid grid(grid_options);
    const LikelihoodFieldOptions options = FieldAt(threshold);
    LikelihoodField followed(options);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Pose2 pose;
    for (int round = 0; round < 40; ++round) {
      // A random walk, so the grid grows now and then, to every side. Every pair or triple of
      // draws here is sequenced, the last coordinate first.
      const double theta = 3.0 * u(rng), dy = 0.6 * u(rng), dx = 0.6 * u(rng);
      pose = Pose2(pose.x() + dx, pose.y() + dy, theta);
      grid.InsertScan(RandomScan(rng, 90), pose);
      // Walls appear and go by hand too, some at the grid's edge.
      std::uniform_int_distribution<int> cx(0, grid.width() - 1), cy(0, grid.height() - 1);
      for (int k = 0; k < 30; ++k) {
        const int y = cy(rng);
        const Eigen::Array2i cell(k % 10 == 0 ? 0 : cx(rng), y);
        grid.Set(cell, static_cast<float>(2.0 * u(rng)));
      }
      if (round % 3 == 0) continue;  // several changes between two Follow calls
      followed.Follow(grid);
      LikelihoodField whole(options);
      whole.Update(grid, WholeGrid(grid));
      ASSERT_TRUE(SameBits(followed.view(), whole.view())) << threshold << " round " << round;
      for (int w = 0; w < 5; ++w) {
        const Eigen::Vector2d a = grid.CellCenter({cx(rng), cy(rng)});
        const double height = 3.0 * u(rng);
        const Eigen::Vector2d b = a + Eigen::Vector2d(3.0 * u(rng), height);
        Eigen::AlignedBox2d region(a.cwiseMin(b), a.cwiseMax(b));
        LikelihoodField window(options);
        window.Update(grid, region);
        ASSERT_TRUE(SameBits(followed.view(region), window.view())) << threshold << " " << round;
      }
    }
  }
}

// Property: following a window that slides with a robot on a long walk (the grid grows past it,
// the window is redone when the region leaves it, walls change in and just outside it), every
// region given to Follow reads bit for bit what a recompute of that region gives, and the field
// stays a window, not the whole map.
TEST(LikelihoodFieldTest, FollowingASlidingRegionEqualsARecomputeOfThatRegion) {
  for (const float threshold : {0.0f, -0.2f}) {
    std::mt19937 rng(3);
    const OccupancyGridOptions grid_options = GrowingGrid(0.5);
    OccupancyGrid grid(grid_options);
    const LikelihoodFieldOptions options = FieldAt(threshold);
    LikelihoodField followed(options);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Pose2 pose;
    int narrower = 0;
    // Below 0 the unknown cells are walls: every growth redoes the window, fewer rounds do.
    const int rounds = threshold < 0.0f ? 30 : 80;
    for (int round = 0; round < rounds; ++round) {
      // Mostly ahead along +x and +y, so the walk leaves the window and the grid grows.
      const double theta = 3.0 * u(rng), dy = 0.3 + 0.5 * u(rng), dx = 0.55 + 0.4 * u(rng);
      pose = Pose2(pose.x() + dx, pose.y() + dy, theta);
      grid.InsertScan(RandomScan(rng, 90), pose);
      // Walls set by hand near the robot, some beyond the region's edge.
      for (int k = 0; k < 10; ++k) {
        const double y = 6.0 * u(rng);
        const Eigen::Array2i cell =
            grid.WorldToCell(pose.translation() + Eigen::Vector2d(6.0 * u(rng), y));
        if (grid.Contains(cell)) grid.Set(cell, static_cast<float>(2.0 * u(rng)));
      }
      const Eigen::Vector2d reach = Eigen::Vector2d::Constant(4.5);
      const Eigen::AlignedBox2d region(pose.translation() - reach, pose.translation() + reach);
      followed.Follow(grid, region);
      LikelihoodField fresh(options);
      fresh.Update(grid, region);
      ASSERT_TRUE(SameBits(followed.view(region), fresh.view())) << threshold << " " << round;
      const Eigen::AlignedBox2d inner(pose.translation() - 0.5 * reach,
                                      pose.translation() + 0.3 * reach);
      fresh.Update(grid, inner);
      ASSERT_TRUE(SameBits(followed.view(inner), fresh.view())) << threshold << " " << round;
      narrower += followed.view().width < grid.width() || followed.view().height < grid.height();
    }
    EXPECT_GT(grid.width() * grid_options.resolution_m, 0.5 * rounds);
    EXPECT_GT(narrower, rounds / 2);
  }
}

// The flips the field follows: each recorded once per change, re-based when the grid grows.
TEST(LikelihoodFieldTest, GridRecordsWallFlipsOnItsCurrentLattice) {
  OccupancyGridOptions grid_options;
  grid_options.resolution_m = 0.1;
  grid_options.grow_margin_m = 0.0;
  OccupancyGrid grid(grid_options, Eigen::Vector2d(0, 0), 10, 10);
  grid.Set({3, 4}, 1.0f);  // before recording: not recorded
  grid.RecordWallFlips(0.0f);
  grid.Set({3, 4}, 2.0f);   // still a wall: no flip
  grid.Set({5, 5}, 1.0f);   // a wall appears
  grid.Set({3, 4}, -1.0f);  // a wall goes
  grid.EnsureContains(
      Eigen::AlignedBox2d(Eigen::Vector2d(-0.55, -0.25), Eigen::Vector2d(0.5, 0.5)));
  const Eigen::Array2i shift = grid.WorldToCell({0.05, 0.05});
  ASSERT_TRUE((shift > 0).all());
  const std::vector<Eigen::Array2i> flips = grid.TakeWallFlips();
  ASSERT_EQ(flips.size(), 2u);
  EXPECT_TRUE((flips[0] == Eigen::Array2i(5, 5) + shift).all());
  EXPECT_TRUE((flips[1] == Eigen::Array2i(3, 4) + shift).all());
  EXPECT_TRUE(grid.TakeWallFlips().empty());
}

}  // namespace
}  // namespace slamrig::slam
