#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "scenarios/scenario_spec.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/types/trajectory.h"

namespace slamrig::scenario {

/// What one SLAM configuration produced in a scenario run, and its scores.
struct ConfigResult {
  std::string name;
  SlamAlgorithm algorithm = SlamAlgorithm::kParticleFilter;
  Trajectory estimate;       ///< one pose per processed scan, map frame aligned to truth at t0
  Trajectory mean_estimate;  ///< weighted-mean particle (PF), else equal to `estimate`
  std::optional<slam::OccupancyGrid> map;  ///< in the estimator's own frame (its first scan)
  Pose2 map_from_estimator;                ///< the true pose at the estimator's first scan
  std::vector<double> neff_time_s;         ///< PF: Neff after each scan (times in seconds)
  std::vector<double> neff;
  std::map<std::string, double> metrics;  ///< KnownMetrics() names; NaN when not applicable
};

/// One checked expectation.
struct ExpectationOutcome {
  Expectation expectation;
  double value = 0.0;  ///< NaN when the metric could not be computed (a failure)
  bool passed = false;
  std::string Describe() const;  ///< "pf.ate_rmse_m = 0.134 > 0.100 (over by 0.034, 34 %)"
};

/// A finished scenario run.
struct ScenarioResult {
  const ScenarioSpec* spec = nullptr;
  Trajectory truth;  ///< true pose at every lidar scan time (including dropped scans)
  std::optional<slam::OccupancyGrid> truth_map;  ///< true poses, noise-free ranges
  std::vector<ConfigResult> configs;
  double sim_time_s = 0.0;
  int scans = 0;              ///< scans the lidar produced
  int scans_blacked_out = 0;  ///< of them, withheld by lidar_blackout faults
  int kidnaps_done = 0;
  std::vector<ExpectationOutcome> outcomes;
  bool passed = true;
};

/// Checks every expectation of `result.spec` against the configs' metrics, filling `outcomes`
/// and `passed`.
void CheckExpectations(ScenarioResult* result);

/// Writes the report folder: config.yaml (resolved), metrics.json, truth.tum and
/// <config>.tum, maps (<config>_map.pgm/.yaml, map.png with truth and estimates), plots
/// (errors over time, Neff over time, metrics per configuration) and report.html.
void WriteReport(const ScenarioResult& result, const std::string& out_dir);

/// The pass/fail table printed at the end of `slamrig run`.
std::string ExpectationTable(const ScenarioResult& result);

}  // namespace slamrig::scenario
