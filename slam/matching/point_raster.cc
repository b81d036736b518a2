#include "slam/matching/point_raster.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <utility>

namespace slamrig::slam {

PointRaster RasterOf(const std::vector<Eigen::Vector2d>& points, double resolution_m,
                     double sigma_m) {
  PointRaster raster;
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const Eigen::Vector2d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const int reach = static_cast<int>(std::ceil(3.0 * sigma_m / resolution_m));
  const double margin = (reach + 1) * resolution_m;
  lo -= Eigen::Vector2d::Constant(margin);
  hi += Eigen::Vector2d::Constant(margin);
  const int width = static_cast<int>(std::ceil((hi.x() - lo.x()) / resolution_m));
  const int height = static_cast<int>(std::ceil((hi.y() - lo.y()) / resolution_m));
  // A cell's value is the largest exp(-d^2 / (2 sigma^2)) over the points within reach, d the
  // distance from the cell's centre: the exp (monotone) of the smallest d^2, taken once per cell
  // rather than once per point and cell.
  std::vector<double> nearest(static_cast<std::size_t>(width) * height,
                              std::numeric_limits<double>::infinity());
  // d^2 = dx^2 + dy^2 from the cell centre's offsets along each axis, each taken once per point.
  std::vector<double> dx2(static_cast<std::size_t>(2 * reach + 1));
  for (const Eigen::Vector2d& p : points) {
    const int cx = static_cast<int>(std::floor((p.x() - lo.x()) / resolution_m));
    const int cy = static_cast<int>(std::floor((p.y() - lo.y()) / resolution_m));
    const int x0 = std::max(0, cx - reach), x1 = std::min(width - 1, cx + reach);
    for (int ix = x0; ix <= x1; ++ix) {
      const double dx = lo.x() + resolution_m * (ix + 0.5) - p.x();
      dx2[static_cast<std::size_t>(ix - x0)] = dx * dx;
    }
    for (int iy = std::max(0, cy - reach); iy <= std::min(height - 1, cy + reach); ++iy) {
      const double dy = lo.y() + resolution_m * (iy + 0.5) - p.y();
      const double dy2 = dy * dy;
      double* row = nearest.data() + static_cast<std::size_t>(iy) * width;
      for (int ix = x0; ix <= x1; ++ix) {
        row[ix] = std::min(row[ix], dx2[static_cast<std::size_t>(ix - x0)] + dy2);
      }
    }
  }
  const double inv_two_var = 1.0 / (2.0 * sigma_m * sigma_m);
  raster.values.assign(nearest.size(), 0.0f);
  for (std::size_t c = 0; c < nearest.size(); ++c) {
    if (nearest[c] == std::numeric_limits<double>::infinity()) continue;
    raster.values[c] = static_cast<float>(std::exp(-nearest[c] * inv_two_var));
  }
  raster.view = GridView{raster.values.data(), width, height, lo, resolution_m};
  return raster;
}

double RasterScore(const PointRaster& raster, const std::vector<Eigen::Vector2d>& points,
                   const Pose2& pose) {
  const GridView& v = raster.view;
  double sum = 0.0;
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d q = pose * p;
    sum += v.At(static_cast<int>(std::floor((q.x() - v.origin.x()) / v.resolution)),
                static_cast<int>(std::floor((q.y() - v.origin.y()) / v.resolution)));
  }
  return points.empty() ? 0.0 : sum / static_cast<double>(points.size());
}

std::vector<Eigen::Vector2d> Thinned(const std::vector<Eigen::Vector2d>& points, double voxel_m) {
  std::set<std::pair<std::int64_t, std::int64_t>> seen;
  std::vector<Eigen::Vector2d> kept;
  for (const Eigen::Vector2d& p : points) {
    const std::pair<std::int64_t, std::int64_t> key{
        static_cast<std::int64_t>(std::floor(p.x() / voxel_m)),
        static_cast<std::int64_t>(std::floor(p.y() / voxel_m))};
    if (seen.insert(key).second) kept.push_back(p);
  }
  return kept;
}

}  // namespace slamrig::slam
