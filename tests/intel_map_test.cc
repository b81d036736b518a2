// Maps intel-corrected from its corrected poses and checks the map against an independent
// raster of the same beams, then round-trips it through map_server files.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <unordered_set>

#include "slam/grid/occupancy_grid.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/map_server.h"
#include "tests/util/dataset.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using CellSet = std::unordered_set<std::int64_t>;

std::int64_t Key(std::int64_t x, std::int64_t y) { return (x << 32) ^ (y & 0xffffffff); }

bool HasNeighbour(const CellSet& cells, std::int64_t key) {
  const std::int64_t x = key >> 32;
  const auto y = static_cast<std::int32_t>(key & 0xffffffff);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      if (cells.count(Key(x + dx, y + dy))) return true;
    }
  }
  return false;
}

// F1 of occupied cells where a cell counts as matched when the other set has a cell within one
// cell (8-neighbourhood).
double ToleranceF1(const CellSet& estimate, const CellSet& truth) {
  std::size_t precise = 0, recalled = 0;
  for (const auto k : estimate) precise += HasNeighbour(truth, k);
  for (const auto k : truth) recalled += HasNeighbour(estimate, k);
  const double p = static_cast<double>(precise) / static_cast<double>(estimate.size());
  const double r = static_cast<double>(recalled) / static_cast<double>(truth.size());
  return 2.0 * p * r / (p + r);
}

TEST(IntelMapTest, OccupiedCellsAgreeWithIndependentEndPointRaster) {
  SLAMRIG_REQUIRE_DATASET(path, "carmen_corrected/intel-corrected.log.gz");
  const slam::CarmenLog log = slam::ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 910u);
  constexpr double kRes = 0.05;

  slam::OccupancyGridOptions options;
  options.resolution_m = kRes;
  slam::OccupancyGrid grid(options);
  for (const auto& s : log.scans) grid.InsertScan(s.scan, s.logged_pose);

  // Independent raster: every return under 30 m, with its own trigonometry, using the other
  // common beam convention (linspace from -90 to +90 degrees), in a cell lattice anchored at 0.
  CellSet raster;
  for (const auto& s : log.scans) {
    const std::size_t n = s.scan.ranges_m.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double r = s.scan.ranges_m[i];
      if (r <= 0.0 || r >= 30.0) continue;
      const double a = s.logged_pose.theta() - std::numbers::pi / 2 +
                       static_cast<double>(i) * std::numbers::pi / static_cast<double>(n - 1);
      raster.insert(
          Key(static_cast<std::int64_t>(std::floor((s.logged_pose.x() + r * std::cos(a)) / kRes)),
              static_cast<std::int64_t>(std::floor((s.logged_pose.y() + r * std::sin(a)) / kRes))));
    }
  }
  CellSet occupied;
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      if (grid.State({x, y}) != slam::CellState::kOccupied) continue;
      const Eigen::Vector2d c = grid.CellCenter({x, y});
      occupied.insert(Key(static_cast<std::int64_t>(std::floor(c.x() / kRes)),
                          static_cast<std::int64_t>(std::floor(c.y() / kRes))));
    }
  }
  ASSERT_GT(occupied.size(), 10000u);
  const double f1 = ToleranceF1(occupied, raster);
  std::printf("intel-corrected at 5 cm: occupied-cell F1 %.3f against the end-point raster\n", f1);
  EXPECT_GE(f1, 0.9);

  // The written map reads back cell for cell.
  testing::TempDir dir;
  const slam::OccupancyGrid back = slam::GridFromMapImage(
      slam::ReadMapServerMap(slam::WriteMapServerMap(grid, dir.File("intel"))));
  int mismatches = 0;
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      mismatches += back.State(back.WorldToCell(grid.CellCenter({x, y}))) != grid.State({x, y});
    }
  }
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
}  // namespace slamrig
