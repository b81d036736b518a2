// slamrig._core: the bench's C++ types and functions for Python. Arrays cross without copies
// where the C++ object owning the buffer can be kept alive (python/arrays.h); the few copies
// are said in the docstrings.

#include "python/core.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>

#include "python/core_internal.h"
#include "python/python_estimator.h"
#include "slam/config/yaml_node.h"
#include "slam/pipeline/python_estimator.h"
#include "slam/types/error.h"

namespace slamrig::python {

using slam::EstimatorConfig;

// A record as a Python object that refers to `owner`'s copy (no copy of its arrays).
py::object RecordRef(const Record& record, py::handle owner) {
  return std::visit(
      [&](const auto& r) {
        return py::cast(&r, py::return_value_policy::reference_internal, owner);
      },
      record);
}

// A record given from Python: one of the record classes.
Record ToRecord(py::handle value) {
  if (py::isinstance<LaserScan>(value)) return value.cast<LaserScan>();
  if (py::isinstance<OdometryPose>(value)) return value.cast<OdometryPose>();
  if (py::isinstance<WheelTicks>(value)) return value.cast<WheelTicks>();
  if (py::isinstance<ImuSample>(value)) return value.cast<ImuSample>();
  throw py::type_error("expected a LaserScan, OdometryPose, WheelTicks or ImuSample, got " +
                       py::repr(value).cast<std::string>());
}

// A trajectory from a Trajectory or an (N, 4) array of t [s], x, y, yaw.
Trajectory ToTrajectory(py::handle value) {
  if (py::isinstance<Trajectory>(value)) return value.cast<Trajectory>();
  const auto rows = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!rows || rows.ndim() != 2 || rows.shape(1) != 4) {
    throw py::value_error("a trajectory is a Trajectory or an (N, 4) array of t, x, y, yaw");
  }
  const auto r = rows.unchecked<2>();
  Trajectory trajectory;
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    trajectory.Append(Time::FromSeconds(r(i, 0)), Pose2(r(i, 1), r(i, 2), r(i, 3)));
  }
  return trajectory;
}

py::dict StatsDict(const slam::ErrorStats& s) {
  py::dict d;
  d["count"] = s.count;
  d["rmse"] = s.rmse;
  d["mean"] = s.mean;
  d["median"] = s.median;
  d["std_dev"] = s.std_dev;
  d["max"] = s.max;
  return d;
}

// JSON is YAML: a dict of options goes through the same strict reader as a scenario's entry.
EstimatorConfig MakeConfig(const std::string& name, const std::string& algorithm,
                           py::dict options) {
  py::dict all(options);
  all["algorithm"] = algorithm;
  const std::string text = py::module_::import("json").attr("dumps")(all).cast<std::string>();
  const YamlNode node = YamlNode::LoadString(text, "EstimatorConfig(" + name + ")");
  EstimatorConfig config = slam::ParseEstimatorConfig(name, node);
  node.CheckAllKeysUsed();
  return config;
}

void DefineCore(py::module_& m, bool embedded) {
  m.doc() = "slamrig's C++ core (use the `slamrig` package).";
  static py::exception<ConfigError> config_error(m, "ConfigError", PyExc_ValueError);
  static py::exception<ParseError> parse_error(m, "ParseError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ConfigError& e) {
      config_error(e.what());
    } catch (const ParseError& e) {
      parse_error(e.what());
    }
  });
  if (!embedded) {
    slam::SetPythonEstimatorFactory(
        [](const slam::PythonEstimatorOptions& options, const slam::EstimatorContext& context) {
          return MakePythonEstimator(options, context, /*embedded=*/false);
        });
  }
  DefineRecords(m);
  DefineTrajectoryAndGrid(m);
  DefineLogs(m);
  DefineSimulator(m);
  DefineEstimatorInputs(m);
  DefineEstimatorRuns(m);
  DefineEvaluation(m);
  DefineScenarioSpec(m);
  DefineScenarioRuns(m);
}

}  // namespace slamrig::python
