#pragma once

#include <Eigen/Core>

#include "slam/grid/occupancy_grid.h"

namespace slamrig::slam {

/// A read-only, non-owning view of a row-major float raster laid over the world: cell (ix, iy)
/// covers [origin.x + ix*res, origin.x + (ix+1)*res) x [origin.y + iy*res, ...), row 0 at the
/// lowest y. Cells outside the raster read as 0. The viewed storage must outlive the view and must
/// not be resized while it is used.
struct GridView {
  const float* values = nullptr;
  int width = 0;
  int height = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  double resolution = 1.0;

  /// The log-odds raster of `grid`.
  static GridView Of(const OccupancyGrid& grid) {
    return GridView{grid.log_odds().data(), grid.width(), grid.height(), grid.origin(),
                    grid.resolution()};
  }
  /// Value of cell (ix, iy), 0 outside.
  float At(int ix, int iy) const {
    if (ix < 0 || iy < 0 || ix >= width || iy >= height) return 0.0f;
    return values[static_cast<std::ptrdiff_t>(iy) * width + ix];
  }
};

}  // namespace slamrig::slam
