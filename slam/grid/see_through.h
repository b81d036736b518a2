#pragma once

#include <Eigen/Core>
#include <optional>
#include <utility>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/grid/ray_trace.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// How many of a scan's rays pass through a wall its map holds.
struct SeeThrough {
  int rays = 0;      ///< returns traced
  int crossing = 0;  ///< of them, rays that cross a wall cell short of their end
  double fraction() const { return rays > 0 ? static_cast<double>(crossing) / rays : 0.0; }
};

/// What a map and a scan at a pose say against each other that a scan matcher cannot see.
/// A likelihood-field or correlative matcher scores where the beams end, never where they pass:
/// on a map written twice (a revisit placed beside the first visit, its walls written across the
/// first visit's rooms), the scan's ends find walls of the second copy and fit it, while its rays
/// cross the first copy's walls. On a map that agrees with itself a ray crosses a wall only where
/// the wall moved (a door, a person) or where it grazes one: a few per cent of the rays.
struct SeeThroughOptions {
  /// A cell holding at least this log-odds is a wall (three of OccupancyGrid's default hits net of
  /// misses: a cell seen once as a hit is not yet one).
  float wall_log_odds = 3.0f;
  /// A ray is traced up to this far short of its end: its own wall, the cells its range noise and
  /// the map's blur make occupied, and a wall it grazes on its way in (within a cell of the ray
  /// over 1 m at three degrees' incidence) are not crossings.
  double end_margin_m = 1.0;
  /// Rays shorter than this are not traced (too little to cross).
  double min_range_m = 1.5;
  int beam_stride = 2;  ///< every this-many returns are traced
};

/// Traces `scan`'s returns (BeamEnds' hits, `max_range_m` as for Grid::InsertScan) seen from
/// `world_from_base` through `map` (an OccupancyGrid or a TiledGrid: LogOdds, WorldToCell,
/// options) and counts those that cross a wall cell before their end; `crossed`, when given, gets
/// the first wall cell each crossing ray met.
template <typename Grid>
SeeThrough CountSeeThrough(const Grid& map, const LaserScan& scan, const Pose2& world_from_base,
                           std::optional<double> max_range_m, const SeeThroughOptions& options,
                           std::vector<Eigen::Array2i>* crossed = nullptr) {
  std::vector<std::pair<Eigen::Vector2d, bool>> ends;
  BeamEnds(scan, world_from_base, map.options(), max_range_m, &ends);
  const Eigen::Vector2d origin = (world_from_base * scan.base_from_laser).translation();
  const Eigen::Array2i start = map.WorldToCell(origin);
  SeeThrough result;
  int hit_index = 0;
  for (const auto& [end, hit] : ends) {
    if (!hit || hit_index++ % options.beam_stride != 0) continue;
    const Eigen::Vector2d ray = end - origin;
    const double length = ray.norm();
    if (length < options.min_range_m) continue;
    const Eigen::Vector2d stop = origin + ray * ((length - options.end_margin_m) / length);
    bool crosses = false;
    TraceRay(start, map.WorldToCell(stop), [&](int x, int y) {
      if (!crosses && map.LogOdds(Eigen::Array2i(x, y)) >= options.wall_log_odds) {
        crosses = true;
        if (crossed != nullptr) crossed->emplace_back(x, y);
      }
    });
    ++result.rays;
    result.crossing += crosses;
  }
  return result;
}

}  // namespace slamrig::slam
