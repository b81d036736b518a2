#pragma once

#include <Eigen/Core>
#include <vector>

#include "slam/matching/grid_view.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// A raster of points with each point blurred by a Gaussian (the maximum where blurs overlap):
/// Olson 2009's rasterised cost, a likelihood field up to scale, values in [0, 1]. What the
/// correlative matcher searches when the reference is a set of points rather than a grid.
struct PointRaster {
  std::vector<float> values;
  GridView view;  ///< over `values`; a PointRaster is not copied (the view would dangle)

  PointRaster() = default;
  PointRaster(const PointRaster&) = delete;
  PointRaster& operator=(const PointRaster&) = delete;
  PointRaster(PointRaster&&) = default;
  PointRaster& operator=(PointRaster&&) = default;
};

/// The raster of `points` (non-empty) at `resolution_m`, each blurred by a Gaussian of standard
/// deviation `sigma_m` out to 3 sigma, with a margin of that reach around their bounding box.
PointRaster RasterOf(const std::vector<Eigen::Vector2d>& points, double resolution_m,
                     double sigma_m);

/// The mean raster value over `points` placed at `pose` (cells outside read 0): the correlative
/// matcher's score at one pose. 0 for no points.
double RasterScore(const PointRaster& raster, const std::vector<Eigen::Vector2d>& points,
                   const Pose2& pose);

/// The first point of each voxel of size `voxel_m`, in the given order.
std::vector<Eigen::Vector2d> Thinned(const std::vector<Eigen::Vector2d>& points, double voxel_m);

}  // namespace slamrig::slam
