#pragma once

#include <vector>

#include "sim/shape_spec.h"
#include "sim/world_spec.h"
#include "slam/io/map_server.h"

namespace slamrig::sim {

/// A rectangle of grid cells: columns [x0, x1) and rows [y0, y1).
struct CellRect {
  int x0 = 0;  ///< first column
  int y0 = 0;  ///< first row (row 0 = lowest y)
  int x1 = 0;  ///< one past the last column
  int y1 = 0;  ///< one past the last row

  /// Field-wise equality.
  friend bool operator==(const CellRect&, const CellRect&) = default;
};

/// Covers the occupied cells of `map` (occupancy >= `options.occupied_min`, and unknown cells
/// when `options.unknown_is_wall`) exactly, with disjoint rectangles: greedy maximal rectangles,
/// each grown first along its row, then upwards while the whole row span stays occupied. A wall
/// of a room's side becomes one rectangle instead of hundreds of cells.
std::vector<CellRect> MergeOccupiedCells(const slam::MapImage& map, const MapImportSpec& options);

/// The rectangles as box shapes in the map frame (the map origin's yaw included).
std::vector<ShapeSpec> MapWallBoxes(const slam::MapImage& map, const MapImportSpec& options);

}  // namespace slamrig::sim
