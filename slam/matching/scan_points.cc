#include "slam/matching/scan_points.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
std::vector<std::string> ScanPointsOptions::Validate() const {
  Rules rules;
  rules.NonNegative("min_range_m", min_range_m)
      .Require(max_range_m > min_range_m, "max_range_m", max_range_m, "must be > min_range_m")
      .AtLeast("beam_stride", beam_stride, 1)
      .NonNegative("voxel_size_m", voxel_size_m)
      .Fraction("sparse_fraction", sparse_fraction);
  return rules.errors();
}

std::optional<double> SparseScanRange(const LaserScan& scan, const ScanPointsOptions& options) {
  if (!(options.sparse_fraction > 0.0) || !(scan.range_max_m > options.max_range_m)) {
    return std::nullopt;
  }
  const double min_range = std::max(options.min_range_m, scan.range_min_m);
  std::size_t near = 0;
  for (const float r : scan.ranges_m) near += r >= min_range && r < options.max_range_m;
  if (static_cast<double>(near) >=
      options.sparse_fraction * static_cast<double>(scan.ranges_m.size())) {
    return std::nullopt;
  }
  return scan.range_max_m;
}

std::vector<Eigen::Vector2d> ScanToBasePoints(const LaserScan& scan,
                                              const ScanPointsOptions& options) {
  SLAMRIG_DCHECK(options.Validate().empty(), "invalid ScanPointsOptions");
  std::vector<Eigen::Vector2d> points;
  points.reserve(scan.ranges_m.size() / static_cast<std::size_t>(options.beam_stride) + 1);
  const double min_range = std::max(options.min_range_m, scan.range_min_m);
  const double max_range =
      std::min(SparseScanRange(scan, options).value_or(options.max_range_m), scan.range_max_m);
  const bool sweeps = scan.Sweeps();
  for (std::size_t i = 0; i < scan.ranges_m.size();
       i += static_cast<std::size_t>(options.beam_stride)) {
    const double r = scan.ranges_m[i];
    if (!(r >= min_range && r < max_range)) continue;
    const double angle = scan.BeamAngle(i);
    const Eigen::Vector2d point =
        scan.base_from_laser * Eigen::Vector2d(r * std::cos(angle), r * std::sin(angle));
    points.push_back(sweeps ? scan.SweepPose(i) * point : point);
  }
  if (options.voxel_size_m <= 0.0 || points.empty()) return points;

  // Voxel filter: sort (voxel key, beam index), keep the first index per key, restore beam order.
  std::vector<std::pair<std::int64_t, std::uint32_t>> keys(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto vx = static_cast<std::int64_t>(std::floor(points[i].x() / options.voxel_size_m));
    const auto vy = static_cast<std::int64_t>(std::floor(points[i].y() / options.voxel_size_m));
    keys[i] = {vx * 4000003 + vy, static_cast<std::uint32_t>(i)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<std::uint32_t> kept;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (i == 0 || keys[i].first != keys[i - 1].first) kept.push_back(keys[i].second);
  }
  std::sort(kept.begin(), kept.end());
  std::vector<Eigen::Vector2d> filtered;
  filtered.reserve(kept.size());
  for (const std::uint32_t i : kept) filtered.push_back(points[i]);
  return filtered;
}

}  // namespace slamrig::slam
