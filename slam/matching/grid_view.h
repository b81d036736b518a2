#pragma once

#include <Eigen/Core>

#include "slam/grid/occupancy_grid.h"

namespace slamrig::slam {

/// A read-only, non-owning view of a row-major float raster laid over the world: cell (ix, iy)
/// covers [origin.x + ix*res, origin.x + (ix+1)*res) x [origin.y + iy*res, ...), row 0 at the
/// lowest y. Cells outside the raster read as 0. The viewed storage must outlive the view and must
/// not be resized while it is used. A view may be a window into a wider raster: rows are then
/// `stride` floats apart.
struct GridView {
  const float* values = nullptr;
  int width = 0;
  int height = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  double resolution = 1.0;
  /// Floats from one row to the next; 0 means `width` (a raster of its own).
  int stride = 0;

  /// Floats from one row to the next.
  int row_stride() const { return stride > 0 ? stride : width; }
  /// The lattice of `grid` without its values (`values` null): for readers that take the values
  /// elsewhere (MapCorrelator with an OccupiedMask). A grid's log-odds are tiles, not one raster:
  /// a window of them is OccupancyGrid::CopyLogOdds.
  static GridView LatticeOf(const OccupancyGrid& grid) {
    return GridView{nullptr, grid.width(), grid.height(), grid.origin(), grid.resolution()};
  }
  /// Value of cell (ix, iy), 0 outside.
  float At(int ix, int iy) const {
    if (ix < 0 || iy < 0 || ix >= width || iy >= height) return 0.0f;
    return values[static_cast<std::ptrdiff_t>(iy) * row_stride() + ix];
  }
};

}  // namespace slamrig::slam
