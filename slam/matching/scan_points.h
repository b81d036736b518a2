#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/types/records.h"

namespace slamrig::slam {

/// Which beams of a scan become points for matching.
struct ScanPointsOptions {
  double min_range_m = 0.1;   ///< shorter returns are dropped (the reports: 0.1-0.2 m)
  double max_range_m = 30.0;  ///< longer returns (and no-returns) are dropped
  int beam_stride = 1;        ///< keep every n-th beam (beam subsampling; 1 keeps all)
  /// Keep the first point (in beam order) of each voxel of this size in the base frame, 0 = off.
  /// Cuts the near-range beams that pile into the same map cells.
  double voxel_size_m = 0.0;

  /// One message per broken rule (prefixed "points.").
  std::vector<std::string> Validate() const;
};

/// The field table of ScanPointsOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, ScanPointsOptions& o) {
  v("min_range_m", o.min_range_m);
  v("max_range_m", o.max_range_m);
  v("beam_stride", o.beam_stride);
  v("voxel_size_m", o.voxel_size_m);
}

/// The scan's hit points in the base_link frame at the scan's time (through scan.base_from_laser,
/// and each beam's SweepPose when the scan sweeps), in beam order.
std::vector<Eigen::Vector2d> ScanToBasePoints(const LaserScan& scan,
                                              const ScanPointsOptions& options);

}  // namespace slamrig::slam
