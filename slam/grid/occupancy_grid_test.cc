#include "slam/grid/occupancy_grid.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace slamrig::slam {
namespace {

// A laser at the origin looking along +x with `n` beams over +-0.1 rad, all reading `range`.
LaserScan FanScan(int n, float range, double range_max = 20.0) {
  LaserScan scan;
  scan.angle_min_rad = -0.1;
  scan.angle_increment_rad = n > 1 ? 0.2 / (n - 1) : 0.0;
  scan.range_min_m = 0.1;
  scan.range_max_m = range_max;
  scan.ranges_m.assign(n, range);
  return scan;
}

OccupancyGridOptions Options() {
  OccupancyGridOptions o;
  o.resolution_m = 0.1;
  o.grow_margin_m = 1.0;
  return o;
}

TEST(OccupancyGridTest, HitsOccupyFreeRaysClearBehindStaysUnknown) {
  OccupancyGrid grid(Options());
  const LaserScan scan = FanScan(1, 2.0f);
  // Beam straight ahead from (0.05, 0.05) so cell boundaries are unambiguous.
  LaserScan one = scan;
  one.angle_min_rad = 0.0;
  EXPECT_EQ(grid.InsertScan(one, Pose2(0.05, 0.05, 0.0)), 1);
  EXPECT_EQ(grid.State(grid.WorldToCell({2.05, 0.05})), CellState::kOccupied);
  EXPECT_FLOAT_EQ(grid.LogOdds(grid.WorldToCell({2.05, 0.05})), Options().hit_log_odds);
  for (double x = 0.05; x < 1.99; x += 0.1) {
    EXPECT_FLOAT_EQ(grid.LogOdds(grid.WorldToCell({x, 0.05})), Options().miss_log_odds) << x;
  }
  EXPECT_EQ(grid.State(grid.WorldToCell({2.25, 0.05})), CellState::kUnknown);
  EXPECT_EQ(grid.State(grid.WorldToCell({1.0, 0.35})), CellState::kUnknown);
}

TEST(OccupancyGridTest, NoReturnBeamsClearWithoutHit) {
  OccupancyGridOptions options = Options();
  options.no_return_clear_range_m = 3.0;
  OccupancyGrid grid(options);
  LaserScan scan = FanScan(1, 20.0f, 20.0);  // reading == range_max: no return
  scan.angle_min_rad = 0.0;
  EXPECT_EQ(grid.InsertScan(scan, Pose2(0.05, 0.05, 0.0)), 0);
  EXPECT_LT(grid.LogOdds(grid.WorldToCell({2.95, 0.05})), 0.0f);
  EXPECT_EQ(grid.LogOdds(grid.WorldToCell({3.25, 0.05})), 0.0f);
  for (const float l : grid.DenseLogOdds()) EXPECT_LE(l, 0.0f);
}

TEST(OccupancyGridTest, RespectsPoseAndLaserMount) {
  OccupancyGrid grid(Options());
  LaserScan scan = FanScan(1, 1.0f);
  scan.angle_min_rad = 0.0;
  scan.base_from_laser = Pose2(0.5, 0.0, 0.0);
  // Robot at (3, 3) facing +y: laser at (3, 3.5), beam ends at (3, 4.5).
  grid.InsertScan(scan, Pose2(3.05, 3.05, std::numbers::pi / 2));
  EXPECT_EQ(grid.State(grid.WorldToCell({3.05, 4.55})), CellState::kOccupied);
  EXPECT_LT(grid.LogOdds(grid.WorldToCell({3.05, 4.0})), 0.0f);
  EXPECT_EQ(grid.LogOdds(grid.WorldToCell({3.05, 3.2})), 0.0f);  // behind the laser
}

// Two beams both straight ahead, the second taken 1 s later after the base has turned a quarter
// turn on the spot: the second hit is 90 degrees to the left of the first, as the world has it.
TEST(OccupancyGridTest, ASweepingScansHitsLandWhereTheBaseWasAtEachBeam) {
  OccupancyGrid grid(Options());
  LaserScan scan = FanScan(2, 2.0f);
  scan.angle_min_rad = 0.0;
  scan.angle_increment_rad = 0.0;
  scan.time_increment_s = 1.0;
  scan.sweep_velocity = {.forward_m_s = 0.0, .yaw_rate_rad_s = std::numbers::pi / 2};
  grid.InsertScan(scan, Pose2(0.05, 0.05, 0.0));
  EXPECT_EQ(grid.State(grid.WorldToCell({2.05, 0.05})), CellState::kOccupied);
  EXPECT_EQ(grid.State(grid.WorldToCell({0.05, 2.05})), CellState::kOccupied);
}

TEST(OccupancyGridTest, HitBehindAWallWithinTheNoiseMarksTheWall) {
  // The wall cell [2.0, 2.1) first; then a beam ending at 2.17, in [2.1, 2.2). With 5 cm range
  // noise the window (2.5 sigma) reaches back to 2.045: the wall's cell takes the hit and the cell
  // behind stays unknown. With exact ranges the cell behind takes it.
  for (const double sigma : {0.0, 0.05}) {
    OccupancyGridOptions options = Options();
    options.range_stddev_m = sigma;
    OccupancyGrid grid(options);
    LaserScan scan = FanScan(1, 2.0f);
    scan.angle_min_rad = 0.0;
    grid.InsertScan(scan, Pose2(0.05, 0.05, 0.0));
    scan.ranges_m[0] = 2.12f;
    grid.InsertScan(scan, Pose2(0.05, 0.05, 0.0));
    const float wall = grid.LogOdds(grid.WorldToCell({2.05, 0.05}));
    const float behind = grid.LogOdds(grid.WorldToCell({2.15, 0.05}));
    if (sigma > 0.0) {
      EXPECT_FLOAT_EQ(wall, 2 * options.hit_log_odds);
      EXPECT_EQ(behind, 0.0f);
    } else {
      EXPECT_FLOAT_EQ(wall, options.hit_log_odds + options.miss_log_odds);
      EXPECT_FLOAT_EQ(behind, options.hit_log_odds);
    }
    // A reading beyond the window marks its own cell.
    scan.ranges_m[0] = 2.25f;
    grid.InsertScan(scan, Pose2(0.05, 0.05, 0.0));
    EXPECT_GT(grid.LogOdds(grid.WorldToCell({2.35, 0.05})), 0.0f) << sigma;
  }
}

TEST(OccupancyGridTest, ClampsLogOdds) {
  OccupancyGrid grid(Options());
  LaserScan scan = FanScan(1, 1.0f);
  scan.angle_min_rad = 0.0;
  for (int i = 0; i < 20; ++i) grid.InsertScan(scan, Pose2(0.05, 0.05, 0.0));
  EXPECT_FLOAT_EQ(grid.LogOdds(grid.WorldToCell({1.05, 0.05})), Options().max_log_odds);
  EXPECT_FLOAT_EQ(grid.LogOdds(grid.WorldToCell({0.55, 0.05})), Options().min_log_odds);
}

TEST(OccupancyGridTest, OncePerScanKeepsGrazedWallCells) {
  // Many beams end in the same cells: with once-per-scan each cell changes by at most one update.
  OccupancyGridOptions options = Options();
  OccupancyGrid once(options);
  options.update_once_per_scan = false;
  OccupancyGrid every(options);
  const LaserScan scan = FanScan(200, 3.0f);
  once.InsertScan(scan, Pose2());
  every.InsertScan(scan, Pose2());
  for (const float l : once.DenseLogOdds()) {
    EXPECT_TRUE(l == 0.0f || l == options.hit_log_odds || l == options.miss_log_odds) << l;
  }
  EXPECT_FLOAT_EQ(every.LogOdds(every.WorldToCell({1.0, 0.0})), options.min_log_odds);
}

TEST(OccupancyGridTest, GrowingKeepsContentsAligned) {
  OccupancyGrid grid(Options());
  LaserScan scan = FanScan(30, 2.0f);
  grid.InsertScan(scan, Pose2(0.0, 0.0, 0.3));
  std::vector<std::pair<Eigen::Vector2d, float>> before;
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width(); ++ix) {
      const float l = grid.LogOdds({ix, iy});
      if (l != 0.0f) before.emplace_back(grid.CellCenter({ix, iy}), l);
    }
  }
  ASSERT_FALSE(before.empty());
  const int old_width = grid.width();
  grid.EnsureContains(Eigen::AlignedBox2d(Eigen::Vector2d(-40, -30), Eigen::Vector2d(25, 50)));
  EXPECT_GT(grid.width(), old_width);
  for (const auto& [center, l] : before) {
    EXPECT_EQ(grid.LogOdds(grid.WorldToCell(center)), l);
    EXPECT_NEAR((grid.CellCenter(grid.WorldToCell(center)) - center).norm(), 0.0, 1e-9);
  }
  EXPECT_TRUE(grid.Contains(grid.WorldToCell({-40, -30})));
  EXPECT_TRUE(grid.Contains(grid.WorldToCell({25, 50})));
}

// A robot driving from the centre out along a diagonal one way, then the other way along a
// parallel line, a scan every metre: the grid grows right, down, left and up many times. Cell sizes
// and margins are powers of two, so every lattice origin is exact and a grid sized up front sees
// the same cells.
std::vector<std::pair<LaserScan, Pose2>> DiagonalRoute() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::pair<LaserScan, Pose2>> scans;
  for (int k = 0; k < 160; ++k) {
    const double s = k < 80 ? k : 80 - k;  // out one way, then the other
    const double offset = k < 80 ? 0.0 : 6.0;
    const double heading = 2.0 * std::numbers::pi * u(rng);
    const Pose2 pose(0.5 * s, -0.4 * s + offset, heading);
    LaserScan scan = FanScan(90, 0.0f, 12.0);
    scan.angle_min_rad = -1.5;
    scan.angle_increment_rad = 3.0 / 89.0;
    for (float& r : scan.ranges_m) {
      const double kind = u(rng);
      r = kind < 0.1 ? 12.0f : static_cast<float>(0.3 + 9.0 * u(rng));
    }
    scans.emplace_back(std::move(scan), pose);
  }
  return scans;
}

TEST(OccupancyGridTest, GrownGridHoldsTheCellsOfAGridSizedUpFrontInTilesItWrote) {
  OccupancyGridOptions options;
  options.resolution_m = 0.0625;
  options.grow_margin_m = 2.0;
  const std::vector<std::pair<LaserScan, Pose2>> route = DiagonalRoute();
  OccupancyGrid grown(options);
  int growths = 0;
  for (const auto& [scan, pose] : route) {
    const int width = grown.width(), height = grown.height();
    grown.InsertScan(scan, pose);
    growths += grown.width() != width || grown.height() != height;
  }
  ASSERT_GE(growths, 16);
  OccupancyGrid sized(options, grown.origin(), grown.width(), grown.height());
  for (const auto& [scan, pose] : route) sized.InsertScan(scan, pose);
  ASSERT_EQ(sized.width(), grown.width());  // it never grew

  const std::vector<float> dense = grown.DenseLogOdds();
  ASSERT_EQ(dense, sized.DenseLogOdds());
  // The dense copy against cell-by-cell reads, and the observed box against a brute-force one.
  Eigen::AlignedBox2i observed;
  int nonzero = 0;
  for (int y = 0; y < grown.height(); ++y) {
    for (int x = 0; x < grown.width(); ++x) {
      const float l = grown.LogOdds({x, y});
      ASSERT_EQ(dense[static_cast<std::size_t>(y) * grown.width() + x], l);
      if (l != 0.0f) {
        observed.extend(Eigen::Vector2i(x, y));
        ++nonzero;
      }
    }
  }
  ASSERT_GT(nonzero, 50000);
  EXPECT_EQ(grown.ObservedCells().min(), observed.min());
  EXPECT_EQ(grown.ObservedCells().max(), observed.max());
  // Windows anywhere, partly or wholly outside the grid, with a wider stride.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> corner(-300, grown.width() + 100);
  std::uniform_int_distribution<int> side(1, 250);
  for (int trial = 0; trial < 100; ++trial) {
    const int lo_x = corner(rng);
    const Eigen::Array2i lo(lo_x, corner(rng) * grown.height() / grown.width());
    const int size_x = side(rng);
    const Eigen::Array2i size(size_x, side(rng));
    const int stride = size.x() + 3;
    std::vector<float> window(static_cast<std::size_t>(stride) * size.y(), -7.0f);
    grown.CopyLogOdds(lo, size, window.data(), stride);
    for (int y = 0; y < size.y(); ++y) {
      for (int x = 0; x < size.x(); ++x) {
        ASSERT_EQ(window[static_cast<std::size_t>(y) * stride + x],
                  grown.LogOdds(lo + Eigen::Array2i(x, y)))
            << trial;
      }
      ASSERT_EQ(window[static_cast<std::size_t>(y) * stride + size.x()], -7.0f);  // padding kept
    }
  }
  // Memory follows the ground covered, not the bounding box: the route's band of the box.
  const double box_tiles = static_cast<double>(grown.width()) * grown.height() / (64.0 * 64.0);
  EXPECT_LT(grown.num_tiles(), 0.5 * box_tiles);
}

TEST(OccupancyGridTest, WorldCellRoundTripWithinHalfCell) {
  OccupancyGrid grid(Options());
  grid.EnsureContains(Eigen::AlignedBox2d(Eigen::Vector2d(-10, -10), Eigen::Vector2d(10, 10)));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coord(-10.0, 10.0);
  for (int i = 0; i < 10000; ++i) {
    const double y = coord(rng);  // drawn first: the order these cases were generated in
    const Eigen::Vector2d p(coord(rng), y);
    const Eigen::Vector2d c = grid.CellCenter(grid.WorldToCell(p));
    ASSERT_LE((c - p).cwiseAbs().maxCoeff(), 0.05 + 1e-12);
  }
}

TEST(OccupancyGridOptionsTest, ValidateNamesFieldValueAndRule) {
  OccupancyGridOptions o;
  o.resolution_m = 0.0;
  o.miss_log_odds = 0.5f;
  EXPECT_THAT(o.Validate(), ::testing::ElementsAre("resolution_m = 0; must be > 0",
                                                   "miss_log_odds = 0.5; must be < 0"));
  o = OccupancyGridOptions();
  o.range_stddev_m = -0.01;
  o.hit_window_sigmas = -1.0;
  EXPECT_THAT(o.Validate(), ::testing::ElementsAre("range_stddev_m = -0.01; must be >= 0",
                                                   "hit_window_sigmas = -1; must be >= 0"));
  EXPECT_TRUE(OccupancyGridOptions().Validate().empty());
}

}  // namespace
}  // namespace slamrig::slam
