#pragma once

#include <Eigen/Core>
#include <optional>
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
  /// A sparse scan, fewer than this fraction of whose beams return within max_range_m (an open
  /// field, dark facades), keeps every return out to the lidar's own range instead: far points
  /// place a scan where near ones are too few to, and max_range_m's reason (grazing and
  /// see-through returns in buildings) does not arise where there is nothing near. 0: never.
  double sparse_fraction = 0.0;

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of ScanPointsOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, ScanPointsOptions& o) {
  v("min_range_m", o.min_range_m);
  v("max_range_m", o.max_range_m);
  v("beam_stride", o.beam_stride);
  v("voxel_size_m", o.voxel_size_m);
  v("sparse_fraction", o.sparse_fraction);
}

/// The range out to which `scan`'s returns are used: the lidar's range_max_m when the scan is
/// sparse (ScanPointsOptions::sparse_fraction), else none (max_range_m holds). The grids'
/// InsertScan takes it, so that a map holds what its matcher reads.
std::optional<double> SparseScanRange(const LaserScan& scan, const ScanPointsOptions& options);

/// The scan's hit points in the base_link frame at the scan's time (through scan.base_from_laser,
/// and each beam's SweepPose when the scan sweeps), in beam order.
std::vector<Eigen::Vector2d> ScanToBasePoints(const LaserScan& scan,
                                              const ScanPointsOptions& options);

}  // namespace slamrig::slam
