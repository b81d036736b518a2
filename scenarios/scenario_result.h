#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "scenarios/scenario_spec.h"
#include "scenarios/texture_run.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/types/trajectory.h"

namespace slamrig::scenario {

/// What one SLAM configuration produced in a scenario run, and its scores. Trajectories are
/// in the reference's frame: the estimator's frame placed at the reference pose of its first scan.
struct ConfigResult {
  std::string name;
  std::string algorithm;
  Trajectory estimate;  ///< the final trajectory (revised where the estimator revises its past)
  Trajectory online;    ///< the poses the estimator reported as it ran
  Trajectory mean_estimate;  ///< the estimator's second estimate (a PF's mean), else empty
  slam::EstimatorRun run;    ///< everything it produced, in its own frame (map, traces, stats)
  Pose2 map_from_estimator;  ///< the reference pose at the estimator's first scan
  /// The ATE alignment of `estimate` to the reference (identity without one).
  Pose2 reference_from_estimate;
  /// False when the configuration reported no map (an external program that wrote none): it
  /// has no map metrics.
  bool has_map = true;
  /// The MetricsOf() names that apply to this configuration in this run (a reference, a camera,
  /// kidnappings, covariances, loop closures); NaN where one applies but could not be computed
  /// (a run too short for a spacing).
  std::map<std::string, double> metrics;
  /// The pose NEES against the reference at each scan with a covariance (empty without), and
  /// the scans' times in seconds.
  std::vector<double> nees_time_s;
  std::vector<double> nees;
  /// Per run.loop_closures entry: agrees with the reference (empty without one).
  std::vector<bool> loop_is_true;
  /// The floor texture mapped with `estimate` (a run with a camera), else none.
  std::optional<TextureResult> texture;
};

/// A configuration that produced nothing to score (an external program that crashed, timed out
/// or wrote no usable output): the other configurations' results stand, the run's verdict is
/// FAIL and this line says why.
struct ConfigFailure {
  std::string name;
  std::string algorithm;
  std::string message;  ///< one line, with the last lines of the program's stderr
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
  /// The reference: the true pose at every lidar scan time (including dropped scans) of a
  /// simulation, or a log's own reference (corrected poses, TRUEPOS); empty when it has none.
  Trajectory truth;
  std::string reference_kind = "ground truth";  ///< what `truth` is, for legends
  /// The map to score against: true poses and noise-free ranges (simulation), or the log's
  /// scans inserted at its reference poses.
  std::optional<slam::OccupancyGrid> truth_map;
  std::vector<ConfigResult> configs;
  /// The configurations that failed, in the scenario's order (not in `configs`).
  std::vector<ConfigFailure> failures;
  double sim_time_s = 0.0;    ///< simulated seconds, or the log's time span
  int scans = 0;              ///< scans the lidar produced (or the log holds)
  int scans_blacked_out = 0;  ///< of them, withheld by lidar_blackout faults
  int kidnaps_done = 0;
  std::vector<Time> kidnap_times;  ///< when each kidnapping happened (data time)
  int frames = 0;                  ///< RGB-D frames in the records (the camera's, or a log's)
  /// A run with a camera: the true floor texture and the map from the true poses (the `truth`
  /// pseudo-configuration's texture metrics, TruthMetrics()), else none.
  std::optional<cv::Mat3b> true_texture;
  std::optional<TextureResult> truth_texture;
  std::map<std::string, double> truth_metrics;
  std::vector<std::string> notes;  ///< what the source said (a log's quirks), for the user
  /// The log was cut short and read up to the cut: where, and what was recovered (also among
  /// `notes`); empty for a whole log or a simulation.
  std::string truncated;
  std::string log_format;  ///< a log's format (slam::Dataset::format), else empty
  /// A log whose stamps were unusable: its times were made up from line order, so sim_time_s is
  /// no duration and no configuration has a realtime_factor.
  bool times_synthesised = false;
  std::vector<ExpectationOutcome> outcomes;
  bool passed = true;
  /// A recorded run (RunnerOptions::record_path): the path run.mcap goes to. The file waits as
  /// `recording`.partial until WriteReport renames it, after it removed metrics.json.
  std::string recording;
};

/// Checks every expectation of `result.spec` against the configs' metrics, filling `outcomes`
/// and `passed`; a failed configuration fails the run (and its expectations, which have no
/// value).
void CheckExpectations(ScenarioResult* result);

/// Writes the report folder: config.yaml (resolved), metrics.json, truth.tum and
/// <config>.tum, maps (<config>_map.pgm/.yaml, map.png with truth and estimates), plots
/// (errors over time, Neff over time, metrics per configuration) and report.html, and renames a
/// recording (`recording`.partial) into place. Every file is
/// written atomically and metrics.json last (an earlier one is removed first), so a folder with
/// a metrics.json is complete. Throws OutputError naming the file that cannot be written,
/// Interrupted after SIGINT/SIGTERM.
void WriteReport(const ScenarioResult& result, const std::string& out_dir);

/// The pass/fail table printed at the end of `slamrig run`.
std::string ExpectationTable(const ScenarioResult& result);

}  // namespace slamrig::scenario
