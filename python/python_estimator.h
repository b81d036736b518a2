#pragma once

// The C++ side of an estimator written in Python: an slam::Estimator that calls a Python
// object's methods under the GIL, so the runner, reports, sweeps and live view treat it like
// any built-in algorithm.

#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/python_estimator.h"

namespace slamrig::python {

namespace py = pybind11;
using slam::OccupancyGrid;
using slam::OccupancyGridOptions;

/// Imports `options.module` (from `options.path`, then sys.path), calls `options.class_name`
/// with the free options as keywords (and `seed=`, `robot=` when it takes them), and wraps the
/// object. `embedded`: the interpreter runs inside the command line, so a Python exception
/// becomes one line (a std::runtime_error) instead of passing through to a Python caller.
std::unique_ptr<slam::Estimator> MakePythonEstimator(const slam::PythonEstimatorOptions& options,
                                                     const slam::EstimatorContext& context,
                                                     bool embedded);

/// A grid of (H, W) log-odds (row 0 at the lowest y) whose cell (0, 0) has its lower-left corner
/// at `origin`; `where` prefixes the errors.
OccupancyGrid GridFromLogOdds(py::handle log_odds, const std::vector<double>& origin,
                              double resolution, const std::string& where);

/// The options of a Python object (a class, a factory or an estimator instance) passed from
/// Python; the object is held with the GIL taken on release.
slam::PythonEstimatorOptions OptionsForObject(py::object object, py::dict kwargs);

}  // namespace slamrig::python
