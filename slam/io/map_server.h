#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// An occupancy map as ROS map_server loads it (nav_msgs/OccupancyGrid semantics).
struct MapImage {
  int width = 0;
  int height = 0;
  double resolution_m = 0.0;
  Pose2 origin;  ///< pose of the lower-left pixel's corner in the map frame
  /// Row-major, row 0 = lowest y (the image's bottom row): -1 unknown, 0 free .. 100 occupied.
  std::vector<std::int8_t> occupancy;

  std::int8_t at(int x, int y) const {
    return occupancy[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                     static_cast<std::size_t>(x)];
  }
};

/// How to write a map for map_server.
struct MapServerWriteOptions {
  double occupied_thresh = 0.65;  ///< probability above which a cell is occupied
  double free_thresh = 0.196;     ///< probability below which a cell is free
  /// "trinary": 0 occupied, 254 free, 205 unknown (map_saver's output);
  /// "scale": grey level 255 * (1 - p), unknown 205.
  std::string mode = "trinary";
};

/// Writes `<base>.pgm` (binary P5, top row = highest y) and `<base>.yaml` for `grid`, cropped
/// to the observed cells, each file atomically. Returns the YAML path.
std::string WriteMapServerMap(const OccupancyGrid& grid, const std::string& base,
                              const MapServerWriteOptions& options = {});

/// Reads a map_server YAML (image, resolution, origin, negate, occupied_thresh, free_thresh,
/// optional mode: trinary|scale|raw) and its image (PGM P5/P2 directly, other formats through
/// OpenCV). Throws ConfigError/ParseError naming the file, line and key.
MapImage ReadMapServerMap(const std::string& yaml_path);

/// A log-odds grid with `map`'s geometry (the origin yaw is ignored, as map_server users do):
/// occupied cells get +`log_odds`, free cells -`log_odds`, unknown 0.
OccupancyGrid GridFromMapImage(const MapImage& map, float log_odds = 5.0f);

}  // namespace slamrig::slam
