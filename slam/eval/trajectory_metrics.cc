#include "slam/eval/trajectory_metrics.h"

namespace slamrig::slam {

TrajectoryMetrics EvaluateTrajectory(const Trajectory& estimate, const Trajectory& reference,
                                     const AssociationOptions& options) {
  TrajectoryMetrics m;
  m.estimate_poses = static_cast<int>(estimate.size());
  m.reference_poses = static_cast<int>(reference.size());
  m.ate = ComputeAte(estimate, reference, options);
  m.matched_poses = m.ate.translation_m.count;
  m.rpe_per_scan = ComputeRpe(estimate, reference, 0.0, options);
  m.rpe_1m = ComputeRpe(estimate, reference, 1.0, options);
  m.rpe_10m = ComputeRpe(estimate, reference, 10.0, options);
  return m;
}

void WriteErrorStats(JsonWriter& json, const std::string& key, const ErrorStats& stats) {
  json.BeginObject(key)
      .Integer("count", stats.count)
      .Number("rmse", stats.rmse)
      .Number("mean", stats.mean)
      .Number("median", stats.median)
      .Number("std", stats.std_dev)
      .Number("max", stats.max)
      .EndObject();
}

namespace {

void WriteRpe(JsonWriter& json, const std::string& key, const RpeResult& rpe) {
  json.BeginObject(key).Number("distance_m", rpe.distance_m);
  WriteErrorStats(json, "translation_m", rpe.translation_m);
  WriteErrorStats(json, "rotation_rad", rpe.rotation_rad);
  json.EndObject();
}

}  // namespace

void WriteTrajectoryMetrics(JsonWriter& json, const TrajectoryMetrics& m) {
  json.Integer("estimate_poses", m.estimate_poses)
      .Integer("reference_poses", m.reference_poses)
      .Integer("matched_poses", m.matched_poses);
  json.BeginObject("ate");
  WriteErrorStats(json, "translation_m", m.ate.translation_m);
  WriteErrorStats(json, "rotation_rad", m.ate.rotation_rad);
  json.BeginObject("alignment")
      .Number("x_m", m.ate.reference_from_estimate.x())
      .Number("y_m", m.ate.reference_from_estimate.y())
      .Number("yaw_rad", m.ate.reference_from_estimate.theta())
      .EndObject();
  json.EndObject();
  WriteRpe(json, "rpe_per_scan", m.rpe_per_scan);
  WriteRpe(json, "rpe_1m", m.rpe_1m);
  WriteRpe(json, "rpe_10m", m.rpe_10m);
}

}  // namespace slamrig::slam
