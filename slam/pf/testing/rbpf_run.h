// Shared by the RBPF's unit tests and its longer synthetic runs: the short office run, a filter
// run over it that keeps what the tests look at, and small options that run fast.
#pragma once

#include <vector>

#include "slam/odometry/scan_sync.h"
#include "slam/pf/rbpf.h"
#include "slam/pf/testing/synthetic_run.h"

namespace slamrig::slam::rbpf_testing {

using ShortRun = slam::testing::ShortOfficeRun;
inline const ShortRun& GetShortRun() { return slam::testing::GetShortOfficeRun(); }

inline double PositionRmse(const std::vector<Pose2>& estimate,
                           const std::vector<GroundTruthPose>& truth) {
  return slam::testing::AnchoredPositionRmse(estimate, truth);
}

inline RbpfOptions FastOptions() {
  RbpfOptions options;
  options.num_particles = 20;
  options.seed = 5;
  return options;
}

struct RbpfRun {
  std::vector<Pose2> online;
  std::vector<Pose2> updates;  // the best particle's path at the end
  int resamples = 0;
  int odometry_rejections = 0;
};

inline RbpfRun RunFilter(const std::vector<SyncedScan>& scans, const RbpfOptions& options) {
  Rbpf filter(options);
  RbpfRun run;
  for (const SyncedScan& s : scans)
    run.online.push_back(filter.AddScan(s.scan, s.increment).best_pose);
  run.updates = filter.BestUpdatePoses();
  run.resamples = filter.resample_count();
  run.odometry_rejections = filter.odometry_rejections();
  return run;
}

}  // namespace slamrig::slam::rbpf_testing
