// The pieces of slamrig._core (python/core.cc's DefineCore): one Define* function per group of
// bindings, in the order DefineCore calls them (a class is registered before the signatures that
// name it), and the conversions they share.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/pipeline/estimator_config.h"
#include "slam/types/records.h"
#include "slam/types/trajectory.h"

namespace slamrig::python {

namespace py = pybind11;

/// A record as a Python object that refers to `owner`'s copy (no copy of its arrays).
py::object RecordRef(const Record& record, py::handle owner);

/// A record given from Python: one of the record classes (TypeError otherwise).
Record ToRecord(py::handle value);

/// A trajectory from a Trajectory or an (N, 4) array of t [s], x, y, yaw (ValueError otherwise).
Trajectory ToTrajectory(py::handle value);

/// An ErrorStats as a dict: count, rmse, mean, median, std_dev, max.
py::dict StatsDict(const slam::ErrorStats& s);

/// A configuration from keyword options, read by the same strict reader as a scenario's entry.
slam::EstimatorConfig MakeConfig(const std::string& name, const std::string& algorithm,
                                 py::dict options);

/// A scenario result with the spec it points at.
struct ScenarioRun {
  std::shared_ptr<scenario::ScenarioSpec> spec;
  scenario::ScenarioResult result;
};

/// Pose2 and the record classes (LaserScan, OdometryPose, WheelTicks, ImuSample).
void DefineRecords(py::module_& m);
/// Trajectory, DiffDriveParams and OccupancyGrid.
void DefineTrajectoryAndGrid(py::module_& m);
/// Dataset, read_log and data_dir.
void DefineLogs(py::module_& m);
/// TruthSample, StepResult and Simulator.
void DefineSimulator(py::module_& m);
/// What goes into an estimator: ScanEstimate, SyncedScan, OdometrySource, ScanSynchronizer and
/// EstimatorConfig, with the helpers resolve_odometry_source, estimator_seed, algorithm_names.
void DefineEstimatorInputs(py::module_& m);
/// Estimator, EstimatorRun, EstimatorRunner and run_estimator.
void DefineEstimatorRuns(py::module_& m);
/// ate, rpe, score_map, score_loop_closures, nees and anees_bounds.
void DefineEvaluation(py::module_& m);
/// ScenarioSpec, load_scenario and ConfigResult.
void DefineScenarioSpec(py::module_& m);
/// ScenarioResult and run_scenario.
void DefineScenarioRuns(py::module_& m);

}  // namespace slamrig::python
