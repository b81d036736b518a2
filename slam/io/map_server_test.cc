#include "slam/io/map_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using ::testing::HasSubstr;

OccupancyGrid RandomGrid() {
  OccupancyGridOptions options;
  options.resolution_m = 0.05;
  OccupancyGrid grid(options);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  std::uniform_real_distribution<double> range(0.5, 6.0);
  LaserScan scan;
  scan.angle_min_rad = -2.0;
  scan.angle_increment_rad = 0.01;
  scan.range_min_m = 0.1;
  scan.range_max_m = 8.0;
  for (int s = 0; s < 20; ++s) {
    scan.ranges_m.clear();
    for (int i = 0; i < 400; ++i) scan.ranges_m.push_back(static_cast<float>(range(rng)));
    grid.InsertScan(scan, Pose2(0.3 * s, -0.1 * s, angle(rng)));
  }
  return grid;
}

TEST(MapServerTest, WrittenMapReadsBackToTheSameGrid) {
  testing::TempDir dir;
  const OccupancyGrid grid = RandomGrid();
  const std::string yaml = WriteMapServerMap(grid, dir.File("map"));
  const MapImage map = ReadMapServerMap(yaml);
  EXPECT_DOUBLE_EQ(map.resolution_m, 0.05);
  const OccupancyGrid back = GridFromMapImage(map);
  int checked = 0, occupied = 0;
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      const Eigen::Vector2d center = grid.CellCenter({x, y});
      const Eigen::Array2i cell = back.WorldToCell(center);
      // Same lattice: the centre of a cell maps to the centre of the read-back cell.
      if (back.Contains(cell)) {
        ASSERT_NEAR((back.CellCenter(cell) - center).norm(), 0.0, 1e-6);
      }
      ASSERT_EQ(back.State(cell), grid.State({x, y})) << x << "," << y;
      ++checked;
      occupied += grid.State({x, y}) == CellState::kOccupied;
    }
  }
  EXPECT_GT(occupied, 100);
  EXPECT_GT(checked, 10000);
}

TEST(MapServerTest, ReadsAsciiPgmNegateAndScale) {
  testing::TempDir dir;
  dir.Write("m.pgm", "P2\n# c\n3 2\n255\n0 255 205\n100 200 30\n");
  const MapImage map = ReadMapServerMap(
      dir.Write("m.yaml",
                "image: m.pgm\nresolution: 0.1\norigin: [-1.0, 2.0, 0.0]\nnegate: 1\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n"));
  ASSERT_EQ(map.width, 3);
  ASSERT_EQ(map.height, 2);
  // negate: p = value / 255. Bottom row (y = 0) is the image's last row.
  EXPECT_EQ(map.at(0, 1), 0);    // 0 -> p 0 -> free
  EXPECT_EQ(map.at(1, 1), 100);  // 255 -> occupied
  EXPECT_EQ(map.at(2, 1), 100);  // 205 -> p 0.80 -> occupied
  EXPECT_EQ(map.at(0, 0), -1);   // 100 -> p 0.39 -> unknown
  EXPECT_EQ(map.at(2, 0), 0);    // 30 -> p 0.12 -> free
  EXPECT_DOUBLE_EQ(map.origin.x(), -1.0);
}

TEST(MapServerTest, BadYamlAndImagesNameFileAndKey) {
  testing::TempDir dir;
  auto error = [&](const std::string& yaml) {
    try {
      ReadMapServerMap(dir.Write("bad.yaml", yaml));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string rest =
      "origin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n";
  EXPECT_THAT(error("image: nope.pgm\nresolution: 0.05\n" + rest),
              HasSubstr("bad.yaml:1:8: image: map image"));
  EXPECT_THAT(error("image: x.pgm\nresolution: -1\n" + rest),
              HasSubstr("bad.yaml:2:13: resolution: must be > 0"));
  EXPECT_THAT(error("image: x.pgm\nresolution: 0.05\ncolour: red\n" + rest),
              HasSubstr("bad.yaml:3:1: colour: unknown key"));
  EXPECT_THAT(error("image: x.pgm\nresolution: 0.05\n"),
              HasSubstr("missing required key 'origin'"));
  dir.Write("t.pgm", "P5\n4 4\n255\nab");
  EXPECT_THAT(error("image: t.pgm\nresolution: 0.05\n" + rest), HasSubstr("truncated PGM"));
  // Found while fuzzing map_server maps: a 65535 x 65535 header allocated 4 GiB before the
  // pixels were counted (and P2's pixel loop overflowed int).
  for (const char* magic : {"P5", "P2"}) {
    dir.Write("huge.pgm", std::string(magic) + "\n65535 65535\n255\n1 2 3");
    EXPECT_THAT(error("image: huge.pgm\nresolution: 0.05\n" + rest),
                HasSubstr("huge.pgm: truncated PGM: expected 4294836225 pixels, found 5 bytes"))
        << magic;
  }
}

}  // namespace
}  // namespace slamrig::slam
