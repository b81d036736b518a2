#include "slam/pf/slam_run.h"

#include <algorithm>

namespace slamrig::slam {
namespace {

// Appends with a never-decreasing stamp, counting the scans that needed it.
void AppendMonotonic(Trajectory& trajectory, Time time, const Pose2& pose, int* reordered) {
  if (!trajectory.empty() && time < trajectory.poses().back().time) {
    time = trajectory.poses().back().time;
    if (reordered != nullptr) ++*reordered;
  }
  trajectory.Append(time, pose);
}

}  // namespace

SlamRunResult RunDeadReckoning(const std::vector<SyncedScan>& scans,
                               const OccupancyGridOptions& map_options,
                               const ProgressCallback& progress) {
  SlamRunResult result;
  result.map = OccupancyGrid(map_options);
  const std::vector<Pose2> poses = DeadReckoningPoses(scans);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    result.map.InsertScan(scans[i].scan, poses[i]);
    AppendMonotonic(result.trajectory, scans[i].scan.time, poses[i], &result.reordered_stamps);
    if (progress) progress(i + 1, scans.size());
  }
  result.mean_trajectory = result.trajectory;
  result.mean_neff = 1.0;
  return result;
}

SlamRunResult RunParticleFilter(const std::vector<SyncedScan>& scans,
                                const ParticleFilterOptions& options,
                                const ProgressCallback& progress) {
  SlamRunResult result;
  ParticleFilter filter(options);
  double neff_sum = 0.0;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const ParticleFilterStep step = filter.AddScan(scans[i].scan, scans[i].increment);
    neff_sum += step.neff;
    const Time time = scans[i].scan.time;
    AppendMonotonic(result.trajectory, time, step.best_pose, &result.reordered_stamps);
    AppendMonotonic(result.mean_trajectory, time, step.mean_pose, nullptr);
    if (options.cloud_every_n_scans > 0 &&
        i % static_cast<std::size_t>(options.cloud_every_n_scans) == 0) {
      result.clouds.push_back(ParticleCloud{time, filter.particles()});
    }
    if (progress) progress(i + 1, scans.size());
  }
  result.map = filter.map();
  result.resamples = filter.resample_count();
  result.mean_neff = scans.empty() ? 0.0 : neff_sum / static_cast<double>(scans.size());
  return result;
}

}  // namespace slamrig::slam
