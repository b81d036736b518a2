#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/particle_filter.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// All particles at one scan time.
struct ParticleCloud {
  Time time;
  std::vector<Particle> particles;
};

/// What a whole SLAM run produced. Poses are base_link in the estimator's map frame, which is
/// the pose of the first scan.
struct SlamRunResult {
  Trajectory trajectory;       ///< one pose per scan: the best particle (PF) or odometry (DR)
  Trajectory mean_trajectory;  ///< weighted-mean particle per scan (equals `trajectory` for DR)
  OccupancyGrid map{OccupancyGridOptions{}};
  std::vector<ParticleCloud> clouds;  ///< every `cloud_every_n_scans` scans, if asked for
  int resamples = 0;
  double mean_neff = 0.0;
  /// Scans stamped earlier than their predecessor (logs with a few out-of-order stamps): they
  /// are stamped with the predecessor's time in the trajectories so that times never decrease.
  int reordered_stamps = 0;
};

/// Called after each scan with (scans done, scans total).
using ProgressCallback = std::function<void(std::size_t, std::size_t)>;

/// Dead reckoning: odometry alone, with the map built along it.
SlamRunResult RunDeadReckoning(const std::vector<SyncedScan>& scans,
                               const OccupancyGridOptions& map_options,
                               const ProgressCallback& progress = nullptr);

/// Particle-filter SLAM over the whole run.
SlamRunResult RunParticleFilter(const std::vector<SyncedScan>& scans,
                                const ParticleFilterOptions& options,
                                const ProgressCallback& progress = nullptr);

}  // namespace slamrig::slam
