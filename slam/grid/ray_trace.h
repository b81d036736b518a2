#pragma once

#include <Eigen/Core>
#include <cstdlib>

namespace slamrig::slam {

/// Visits the cells of the 8-connected Bresenham line from `from` to `to`, starting with `from`
/// and stopping before `to` (the end cell is the caller's: a hit, or nothing for a free ray).
/// Visits exactly max(|dx|, |dy|) cells; every visited cell lies within half a cell (measured
/// along the minor axis) of the straight line between the two cell centres.
template <typename Visitor>
void TraceRay(const Eigen::Array2i& from, const Eigen::Array2i& to, Visitor&& visit) {
  const int dx = std::abs(to.x() - from.x());
  const int dy = std::abs(to.y() - from.y());
  const int sx = to.x() >= from.x() ? 1 : -1;
  const int sy = to.y() >= from.y() ? 1 : -1;
  int x = from.x();
  int y = from.y();
  if (dx >= dy) {
    int error = 2 * dy - dx;
    for (int i = 0; i < dx; ++i) {
      visit(x, y);
      if (error > 0) {
        y += sy;
        error -= 2 * dx;
      }
      error += 2 * dy;
      x += sx;
    }
  } else {
    int error = 2 * dx - dy;
    for (int i = 0; i < dy; ++i) {
      visit(x, y);
      if (error > 0) {
        x += sx;
        error -= 2 * dy;
      }
      error += 2 * dx;
      y += sy;
    }
  }
}

}  // namespace slamrig::slam
