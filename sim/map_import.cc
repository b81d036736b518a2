#include "sim/map_import.h"

#include <cmath>

namespace slamrig::sim {

std::vector<CellRect> MergeOccupiedCells(const slam::MapImage& map, const MapImportSpec& options) {
  const int w = map.width, h = map.height;
  auto index = [w](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
  };
  // Cells still to cover.
  std::vector<char> todo(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int value = map.at(x, y);
      todo[index(x, y)] = value >= options.occupied_min || (value < 0 && options.unknown_is_wall);
    }
  }
  std::vector<CellRect> rects;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!todo[index(x, y)]) continue;
      CellRect r{x, y, x + 1, y + 1};
      while (r.x1 < w && todo[index(r.x1, y)]) ++r.x1;
      auto row_full = [&](int row) {
        for (int cx = r.x0; cx < r.x1; ++cx) {
          if (!todo[index(cx, row)]) return false;
        }
        return true;
      };
      while (r.y1 < h && row_full(r.y1)) ++r.y1;
      for (int cy = r.y0; cy < r.y1; ++cy) {
        for (int cx = r.x0; cx < r.x1; ++cx) todo[index(cx, cy)] = 0;
      }
      rects.push_back(r);
    }
  }
  return rects;
}

std::vector<ShapeSpec> MapWallBoxes(const slam::MapImage& map, const MapImportSpec& options) {
  std::vector<ShapeSpec> boxes;
  const double res = map.resolution_m;
  for (const CellRect& r : MergeOccupiedCells(map, options)) {
    ShapeSpec box;
    box.type = ShapeType::kBox;
    const Eigen::Vector2d local_center(0.5 * (r.x0 + r.x1) * res, 0.5 * (r.y0 + r.y1) * res);
    box.center_m = map.origin * local_center;
    box.size_m = Eigen::Vector2d((r.x1 - r.x0) * res, (r.y1 - r.y0) * res);
    box.angle_rad = map.origin.theta();
    boxes.push_back(box);
  }
  return boxes;
}

}  // namespace slamrig::sim
