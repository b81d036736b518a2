#pragma once

#include <string>

#include "slam/eval/json_writer.h"
#include "slam/eval/trajectory_error.h"

namespace slamrig::slam {

/// The standard trajectory scores of one estimate: ATE, and RPE per pose pair, over 1 m and 10 m.
struct TrajectoryMetrics {
  int estimate_poses = 0;
  int reference_poses = 0;
  int matched_poses = 0;
  AteResult ate;
  RpeResult rpe_per_scan;
  RpeResult rpe_1m;
  RpeResult rpe_10m;
};

/// Computes all of TrajectoryMetrics.
TrajectoryMetrics EvaluateTrajectory(const Trajectory& estimate, const Trajectory& reference,
                                     const AssociationOptions& options = {});

/// Writes `stats` as an object under `key`.
void WriteErrorStats(JsonWriter& json, const std::string& key, const ErrorStats& stats);

/// Writes `metrics` as objects "ate", "rpe_per_scan", "rpe_1m", "rpe_10m" plus pose counts.
void WriteTrajectoryMetrics(JsonWriter& json, const TrajectoryMetrics& metrics);

}  // namespace slamrig::slam
