#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// A trajectory to draw over a map, with its legend label and BGR colour.
struct TrajectoryOverlay {
  const Trajectory* trajectory = nullptr;
  std::string label;
  std::uint8_t blue = 0, green = 0, red = 0;
};

/// A line segment to draw over a map (a loop closure between two poses), world frame, BGR.
struct SegmentOverlay {
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  std::uint8_t blue = 0, green = 0, red = 0;
};

/// Rendering of a map picture.
struct MapImageOptions {
  int min_size_px = 800;   ///< small maps are scaled up (nearest) to about this many pixels
  int max_size_px = 4000;  ///< large maps are scaled down to fit
  double margin_m = 1.0;   ///< room around the observed cells and the trajectories
  std::string title;       ///< printed top left, e.g. the log's name
  std::vector<SegmentOverlay> segments;  ///< drawn thin over the trajectories
};

/// A PNG picture of `grid` (occupied black, free white, unknown grey; probability as shade) with
/// the trajectories drawn over it, a legend and a scale bar. Returns the encoded PNG bytes.
std::string RenderMapPng(const OccupancyGrid& grid, const std::vector<TrajectoryOverlay>& overlays,
                         const MapImageOptions& options = {});

/// RenderMapPng written to `path` atomically.
void WriteMapPng(const std::string& path, const OccupancyGrid& grid,
                 const std::vector<TrajectoryOverlay>& overlays,
                 const MapImageOptions& options = {});

}  // namespace slamrig::slam
