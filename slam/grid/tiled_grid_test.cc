#include "slam/grid/tiled_grid.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>

namespace slamrig::slam {
namespace {

// A random scan from a random pose near the origin: mixed hits, no-returns and too-short beams.
struct RandomScan {
  LaserScan scan;
  Pose2 pose;
};

RandomScan MakeRandomScan(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RandomScan r;
  // Sequenced draws, the last coordinate first (the order these cases were generated in).
  const double theta = std::numbers::pi * (2.0 * u(rng) - 1.0), y = -4.0 + 8.0 * u(rng);
  r.pose = Pose2(-4.0 + 8.0 * u(rng), y, theta);
  LaserScan& scan = r.scan;
  const int beams = 20 + static_cast<int>(u(rng) * 200);
  scan.angle_min_rad = -2.0;
  scan.angle_increment_rad = 4.0 / beams;
  scan.range_min_m = 0.1;
  scan.range_max_m = 12.0;
  scan.base_from_laser = Pose2(0.1, -0.05, 0.02);
  for (int i = 0; i < beams; ++i) {
    const double kind = u(rng);
    scan.ranges_m.push_back(kind < 0.1    ? 12.0f  // no return
                            : kind < 0.15 ? 0.05f  // too short
                                          : static_cast<float>(0.2 + 11.0 * u(rng)));
  }
  return r;
}

OccupancyGridOptions Options(bool once) {
  OccupancyGridOptions o;
  o.resolution_m = 0.05;
  o.no_return_clear_range_m = 6.0;
  o.update_once_per_scan = once;
  return o;
}

TEST(TiledGridTest, InsertScanMatchesOccupancyGridCellForCellOnRandomScans) {
  for (const bool once : {true, false}) {
    const Eigen::Vector2d origin(-20.0, -20.0);
    // Large enough never to grow, so both grids keep the same lattice origin.
    OccupancyGrid reference(Options(once), origin, 800, 800);
    TiledGrid tiled(Options(once), origin);
    std::mt19937 rng(7);
    int hits = 0;
    for (int trial = 0; trial < 40; ++trial) {
      RandomScan r = MakeRandomScan(rng);
      if (trial % 2 == 1) {  // every other scan sweeps while the base drives an arc
        r.scan.time_increment_s = 1e-3;
        r.scan.sweep_velocity = {.forward_m_s = 0.7, .yaw_rate_rad_s = -1.3};
      }
      const int expected = reference.InsertScan(r.scan, r.pose);
      EXPECT_EQ(tiled.InsertScan(r.scan, r.pose), expected);
      hits += expected;
    }
    ASSERT_GT(hits, 1000);
    int mismatches = 0, nonzero = 0;
    for (int y = 0; y < reference.height(); ++y) {
      for (int x = 0; x < reference.width(); ++x) {
        const float l = reference.LogOdds({x, y});
        nonzero += l != 0.0f;
        mismatches += tiled.LogOdds(x, y) != l;
      }
    }
    EXPECT_EQ(mismatches, 0) << "once=" << once;
    EXPECT_GT(nonzero, 10000);
    // And the conversion back is the same raster on the same lattice.
    const OccupancyGrid converted = tiled.ToOccupancyGrid();
    int converted_mismatches = 0;
    for (int y = 0; y < converted.height(); ++y) {
      for (int x = 0; x < converted.width(); ++x) {
        const Eigen::Vector2d c = converted.CellCenter({x, y});
        converted_mismatches += converted.LogOdds({x, y}) != tiled.LogOdds(tiled.WorldToCell(c));
      }
    }
    EXPECT_EQ(converted_mismatches, 0);
  }
}

// The hit means against an independent accumulation of the scans' end points per cell; recording
// them leaves the log-odds as they were, and a copy's writes do not reach the original's means.
TEST(TiledGridTest, HitMeansAreTheMeanOfEachCellsEndPoints) {
  const Eigen::Vector2d origin(-20.0, -20.0);
  TiledGrid plain(Options(true), origin);
  TiledGrid means(Options(true), origin);
  means.RecordHitMeans(true);
  EXPECT_TRUE(means.records_hit_means());
  EXPECT_FALSE(plain.records_hit_means());
  struct Sum {
    double x = 0.0, y = 0.0;
    int n = 0;
  };
  std::map<std::pair<int, int>, Sum> expected;
  std::mt19937 rng(11);
  for (int trial = 0; trial < 30; ++trial) {
    const RandomScan r = MakeRandomScan(rng);
    plain.InsertScan(r.scan, r.pose);
    means.InsertScan(r.scan, r.pose);
    const Pose2 laser = r.pose * r.scan.base_from_laser;
    for (std::size_t i = 0; i < r.scan.ranges_m.size(); ++i) {
      const double range = r.scan.ranges_m[i];
      if (range < r.scan.range_min_m || range >= r.scan.range_max_m) continue;
      const double a = laser.theta() + r.scan.BeamAngle(i);
      const Eigen::Vector2d end =
          laser.translation() + range * Eigen::Vector2d(std::cos(a), std::sin(a));
      const int ix = static_cast<int>(std::floor((end.x() - origin.x()) / 0.05));
      const int iy = static_cast<int>(std::floor((end.y() - origin.y()) / 0.05));
      Sum& sum = expected[{ix, iy}];
      sum.x += end.x() - (origin.x() + (ix + 0.5) * 0.05);
      sum.y += end.y() - (origin.y() + (iy + 0.5) * 0.05);
      ++sum.n;
    }
  }
  ASSERT_GT(expected.size(), 1000u);
  int repeated = 0;
  for (const auto& [cell, sum] : expected) {
    const TiledGrid::HitMean m = means.HitMeanAt(cell.first, cell.second);
    ASSERT_EQ(m.count, static_cast<float>(sum.n));
    EXPECT_NEAR(m.dx, sum.x / sum.n, 1e-5);
    EXPECT_NEAR(m.dy, sum.y / sum.n, 1e-5);
    repeated += sum.n > 1;
  }
  EXPECT_GT(repeated, 10);  // the running mean is exercised, not only single hits
  for (int iy = -400; iy < 400; iy += 3) {
    for (int ix = -400; ix < 400; ix += 3) {
      ASSERT_EQ(means.LogOdds(ix, iy), plain.LogOdds(ix, iy));
      if (!expected.count({ix, iy})) {
        ASSERT_EQ(means.HitMeanAt(ix, iy).count, 0.0f);
      }
    }
  }
  // Copy-on-write: the copy's new hits stay out of the original's means.
  TiledGrid copy = means;
  std::mt19937 more(12);
  for (int trial = 0; trial < 5; ++trial) {
    const RandomScan r = MakeRandomScan(more);
    copy.InsertScan(r.scan, r.pose);
  }
  int changed = 0;
  for (const auto& [cell, sum] : expected) {
    EXPECT_EQ(means.HitMeanAt(cell.first, cell.second).count, static_cast<float>(sum.n));
    changed += copy.HitMeanAt(cell.first, cell.second).count != static_cast<float>(sum.n);
  }
  EXPECT_GT(changed, 0);
}

TEST(TiledGridTest, CellsOutsideWrittenTilesAreUnknownIncludingNegativeIndices) {
  TiledGrid grid(Options(true));
  EXPECT_EQ(grid.LogOdds(-1000, 5), 0.0f);
  grid.Update({-1, -1}, 0.5f);
  grid.Update({-65, 64}, -0.25f);
  EXPECT_FLOAT_EQ(grid.LogOdds(-1, -1), 0.5f);
  EXPECT_FLOAT_EQ(grid.LogOdds(-65, 64), -0.25f);
  EXPECT_EQ(grid.LogOdds(0, 0), 0.0f);
  EXPECT_EQ(grid.LogOdds(-64, 64), 0.0f);
  EXPECT_EQ(grid.num_tiles(), 2);
  // Clamped as OccupancyGrid::Update clamps.
  for (int i = 0; i < 100; ++i) grid.Update({-1, -1}, 1.0f);
  EXPECT_FLOAT_EQ(grid.LogOdds(-1, -1), Options(true).max_log_odds);
}

TEST(TiledGridTest, CopiesShareTilesUntilWrittenAndWritesStayPrivate) {
  TiledGrid a(Options(true));
  std::mt19937 rng(3);
  for (int i = 0; i < 5; ++i) {
    const RandomScan r = MakeRandomScan(rng);
    a.InsertScan(r.scan, r.pose);
  }
  const int tiles = a.num_tiles();
  ASSERT_GT(tiles, 20);
  const TiledGrid snapshot = a;  // keeps the values a had, through its own tile table
  TiledGrid b = a;
  EXPECT_EQ(b.SharedTiles(a), tiles);

  // One cell written in b: one tile copied, the rest still shared, a unchanged.
  const Eigen::Array2i cell = b.WorldToCell({1.0, 1.0});
  const float before = a.LogOdds(cell);
  b.Update(cell, 0.7f);
  EXPECT_FLOAT_EQ(b.LogOdds(cell), std::clamp(before + 0.7f, -5.0f, 5.0f));
  EXPECT_EQ(a.LogOdds(cell), before);
  EXPECT_EQ(b.SharedTiles(a), tiles - 1);
  EXPECT_EQ(b.num_tiles(), tiles);

  // A scan inserted into a changes only a: every cell of b still equals the snapshot but `cell`.
  const RandomScan r = MakeRandomScan(rng);
  a.InsertScan(r.scan, r.pose);
  EXPECT_LT(a.SharedTiles(b), tiles - 1);
  EXPECT_GT(a.SharedTiles(b), 0);
  int changed_in_b = 0;
  for (int y = -400; y < 400; ++y) {
    for (int x = -400; x < 400; ++x) changed_in_b += b.LogOdds(x, y) != snapshot.LogOdds(x, y);
  }
  EXPECT_EQ(changed_in_b, 1);
  std::vector<const TiledGrid::Tile*> all;
  a.CollectTiles(&all);
  b.CollectTiles(&all);
  snapshot.CollectTiles(&all);
  std::sort(all.begin(), all.end());
  const auto distinct = std::unique(all.begin(), all.end()) - all.begin();
  // The snapshot shares with a the tiles the new scan missed and with b all but one.
  EXPECT_LT(distinct, 3 * tiles);
  EXPECT_EQ(distinct, a.num_tiles() + tiles + 1 - a.SharedTiles(snapshot));
}

}  // namespace
}  // namespace slamrig::slam
