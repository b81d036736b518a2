#include "sim/map_import.h"

#include <gtest/gtest.h>

#include <string>

namespace slamrig::sim {
namespace {

// A map from rows of text, top row first: '#' occupied, '.' free, '?' unknown.
slam::MapImage MapFromText(const std::vector<std::string>& rows, double resolution,
                           const Pose2& origin = Pose2()) {
  slam::MapImage map;
  map.height = static_cast<int>(rows.size());
  map.width = static_cast<int>(rows[0].size());
  map.resolution_m = resolution;
  map.origin = origin;
  for (int y = 0; y < map.height; ++y) {
    for (const char c : rows[static_cast<std::size_t>(map.height - 1 - y)]) {
      map.occupancy.push_back(c == '#' ? 100 : c == '?' ? -1 : 0);
    }
  }
  return map;
}

TEST(MapImportTest, MergesARoomOutlineIntoFourBoxes) {
  const auto map = MapFromText({"######", "#....#", "#....#", "######"}, 0.1);
  const auto rects = MergeOccupiedCells(map, MapImportSpec{});
  EXPECT_EQ(rects.size(), 4u);
  int cells = 0;
  for (const CellRect& r : rects) cells += (r.x1 - r.x0) * (r.y1 - r.y0);
  EXPECT_EQ(cells, 6 + 6 + 2 + 2);  // every occupied cell exactly once
}

TEST(MapImportTest, CoversExactlyTheOccupiedCells) {
  const auto map = MapFromText({"#..##?", "##.##.", ".#...#", "?####."}, 0.05);
  for (const bool unknown_is_wall : {false, true}) {
    MapImportSpec spec;
    spec.unknown_is_wall = unknown_is_wall;
    std::vector<int> covered(map.occupancy.size(), 0);
    for (const CellRect& r : MergeOccupiedCells(map, spec)) {
      for (int y = r.y0; y < r.y1; ++y) {
        for (int x = r.x0; x < r.x1; ++x) ++covered[static_cast<std::size_t>(y * map.width + x)];
      }
    }
    for (std::size_t i = 0; i < covered.size(); ++i) {
      const int v = map.occupancy[i];
      EXPECT_EQ(covered[i], (v >= 65 || (v < 0 && unknown_is_wall)) ? 1 : 0) << "cell " << i;
    }
  }
}

TEST(MapImportTest, BoxesSitInTheMapFrame) {
  const auto map = MapFromText({"##", ".."}, 0.5, Pose2(10.0, 20.0, std::numbers::pi / 2));
  const auto boxes = MapWallBoxes(map, MapImportSpec{});
  ASSERT_EQ(boxes.size(), 1u);
  // The top row spans x in [0, 1], y in [0.5, 1] of the map image; rotated 90 degrees about
  // the origin (10, 20) its centre (0.5, 0.75) lands at (10 - 0.75, 20 + 0.5).
  EXPECT_NEAR(boxes[0].center_m.x(), 9.25, 1e-12);
  EXPECT_NEAR(boxes[0].center_m.y(), 20.5, 1e-12);
  EXPECT_NEAR(boxes[0].size_m.x(), 1.0, 1e-12);
  EXPECT_NEAR(boxes[0].size_m.y(), 0.5, 1e-12);
  EXPECT_NEAR(boxes[0].angle_rad, std::numbers::pi / 2, 1e-12);
}

}  // namespace
}  // namespace slamrig::sim
