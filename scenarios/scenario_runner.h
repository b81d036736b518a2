#pragma once

#include <functional>
#include <string>

#include "scenarios/scenario_result.h"
#include "scenarios/scenario_spec.h"
#include "slam/io/bag/message_sink.h"

namespace slamrig::scenario {

/// How a scenario run behaves around the run itself (never what it computes).
struct RunnerOptions {
  bool view = false;  ///< open a live window (needs a display)
  /// Record the run as MCAP for Foxglove (RunRecorder) to this path (.partial until WriteReport
  /// renames it); empty: no recording.
  std::string record_path;
  /// The run's live view (LiveServer): every message the recording has, as it is made, with or
  /// without record_path; nullptr: none.
  slam::MessageSink* live = nullptr;
  /// Called with the run's clock after each simulation step (a log: each record), to pace a
  /// live view to the wall clock. It may sleep; it never changes what the run computes.
  std::function<void(Time)> pace;
  /// Called about once per simulated second with (sim time, duration); for progress output.
  std::function<void(double, double)> progress;
  /// A log source: called after each scan the first configuration takes, with the scans taken,
  /// the scans the run will take and that configuration's runner (its estimator's view). It may
  /// be called on a thread other than the caller's (the one that runs the first configuration),
  /// and `progress` too; never two calls at once.
  std::function<void(std::size_t done, std::size_t total, const slam::SyncedScan& scan,
                     const slam::EstimatorRunner& runner)>
      on_scan;
  /// The report folder: an `external` configuration writes its input and output below
  /// `external/<name>/` there, and its program's stdout and stderr beside the report. A scenario
  /// with one and no folder is a ConfigError.
  std::string work_dir;
};

/// Runs a scenario: the simulator, every SLAM configuration and the evaluation advance together
/// on the simulator's clock in this one process. Each physics step's records go through the fault
/// injection (lidar blackouts drop scans; kidnaps move the robot), then to each configuration's
/// scan synchroniser and estimator as soon as a scan's odometry is known, so nothing is dropped
/// or reordered however fast it runs. The run ends when the drive is finished or at duration_s.
/// Deterministic: equal specs give bit-identical trajectories and maps (wall-clock time only
/// enters the realtime_factor metric).
ScenarioResult RunScenario(const ScenarioSpec& spec, const RunnerOptions& options = {});

}  // namespace slamrig::scenario
