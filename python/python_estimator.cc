#include "python/python_estimator.h"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "slam/types/error.h"

namespace slamrig::python {
namespace {

// "ValueError: message" of the Python exception being handled, on one line.
std::string OneLine(const py::error_already_set& e) {
  std::string type = "Exception";
  std::string message;
  try {
    type = py::str(e.type().attr("__name__")).cast<std::string>();
    message = py::str(e.value()).cast<std::string>();
  } catch (...) {
  }
  for (char& c : message) {
    if (c == '\n') c = ' ';
  }
  return message.empty() ? type : type + ": " + message;
}

// A pose from a Pose2 or any sequence of three numbers.
Pose2 ToPose(py::handle value, const std::string& where) {
  if (py::isinstance<Pose2>(value)) return value.cast<Pose2>();
  try {
    const auto xyz = value.cast<std::vector<double>>();
    if (xyz.size() == 3) return Pose2(xyz[0], xyz[1], xyz[2]);
  } catch (const py::cast_error&) {
  }
  throw std::runtime_error(where + ": expected a Pose2 or (x, y, yaw), got " +
                           py::repr(value).cast<std::string>());
}

slam::ScanEstimate ToScanEstimate(py::handle value, const std::string& where) {
  if (py::isinstance<slam::ScanEstimate>(value)) return value.cast<slam::ScanEstimate>();
  if (!py::isinstance<py::dict>(value)) return {ToPose(value, where), {}, {}, {}, {}};
  const auto dict = value.cast<py::dict>();
  slam::ScanEstimate estimate;
  for (const auto& [k, v] : dict) {
    const std::string key = py::str(k);
    if (key == "pose") {
      estimate.pose = ToPose(v, where + "['pose']");
    } else if (key == "mean_pose") {
      if (!v.is_none()) estimate.mean_pose = ToPose(v, where + "['mean_pose']");
    } else if (key == "trace") {
      for (const auto& [name, number] : v.cast<py::dict>()) {
        estimate.trace.push_back({py::str(name), number.cast<double>()});
      }
    } else if (key == "covariance") {
      if (!v.is_none()) estimate.covariance = v.cast<Eigen::Matrix3d>();
    } else {
      throw std::runtime_error(where + ": unknown key '" + key +
                               "'; expected pose, mean_pose, trace, covariance");
    }
  }
  if (!dict.contains("pose")) throw std::runtime_error(where + ": the dict has no 'pose'");
  return estimate;
}

// A grid from an OccupancyGrid, or a (log_odds[H, W], (x0, y0), resolution) tuple.
OccupancyGrid ToGrid(py::handle value, const std::string& where) {
  if (py::isinstance<OccupancyGrid>(value)) return value.cast<OccupancyGrid>();
  const auto parts = value.cast<py::tuple>();
  if (parts.size() != 3) {
    throw std::runtime_error(where +
                             ": expected an OccupancyGrid or (log_odds, (x0, y0), resolution)");
  }
  return GridFromLogOdds(parts[0], parts[1].cast<std::vector<double>>(), parts[2].cast<double>(),
                         where);
}

class PythonEstimator final : public slam::Estimator {
 public:
  PythonEstimator(py::object object, std::string name, bool embedded)
      : object_(std::move(object)), name_(std::move(name)), embedded_(embedded) {
    has_record_ = py::hasattr(object_, "add_record");
    has_record_estimate_ = py::hasattr(object_, "record_estimate");
    if (!py::hasattr(object_, "add_scan")) {
      throw ConfigError(name_ + ": a Python estimator needs an add_scan(scan) method");
    }
  }
  ~PythonEstimator() override {
    py::gil_scoped_acquire gil;
    object_ = py::object();
  }

  void AddRecord(const Record& record) override {
    if (!has_record_) return;
    Call("add_record", [&] {
      object_.attr("add_record")(std::visit([](const auto& r) { return py::cast(r); }, record));
    });
  }
  std::optional<slam::ScanEstimate> RecordEstimate() const override {
    if (!has_record_estimate_) return std::nullopt;
    std::optional<slam::ScanEstimate> estimate;
    Call("record_estimate", [&] {
      const py::object value = object_.attr("record_estimate")();
      if (!value.is_none()) estimate = ToScanEstimate(value, name_ + ".record_estimate()");
    });
    return estimate;
  }
  slam::ScanEstimate AddScan(const slam::SyncedScan& scan) override {
    slam::ScanEstimate estimate;
    Call("add_scan", [&] {
      // The runner's scan is gone after this call; the object gets its own copy, so the arrays
      // it views may be kept.
      const py::object value = object_.attr("add_scan")(std::make_shared<slam::SyncedScan>(scan));
      estimate = ToScanEstimate(value, name_ + ".add_scan()");
    });
    return estimate;
  }
  void Finish() override {
    Call("finish", [&] {
      if (py::hasattr(object_, "finish")) object_.attr("finish")();
    });
  }
  std::optional<std::vector<Pose2>> RevisedPoses() const override {
    std::optional<std::vector<Pose2>> poses;
    Call("revised_poses", [&] {
      if (!py::hasattr(object_, "revised_poses")) return;
      const py::object value = object_.attr("revised_poses")();
      if (value.is_none()) return;
      poses.emplace();
      for (const auto& row : value) poses->push_back(ToPose(row, name_ + ".revised_poses()"));
    });
    return poses;
  }
  const OccupancyGrid& map() const override {
    Call("map", [&] {
      if (!py::hasattr(object_, "map")) return;
      const py::object value = object_.attr("map")();
      if (!value.is_none()) map_ = ToGrid(value, name_ + ".map()");
    });
    return map_;
  }
  std::map<std::string, double> Statistics() const override {
    std::map<std::string, double> statistics;
    Call("statistics", [&] {
      if (!py::hasattr(object_, "statistics")) return;
      statistics = object_.attr("statistics")().cast<std::map<std::string, double>>();
    });
    return statistics;
  }
  std::vector<slam::LoopClosure> LoopClosures() const override {
    std::vector<slam::LoopClosure> closures;
    Call("loop_closures", [&] {
      if (!py::hasattr(object_, "loop_closures")) return;
      for (const auto& item : object_.attr("loop_closures")()) {
        const auto t = item.cast<py::tuple>();
        closures.push_back(
            {t[0].cast<int>(), t[1].cast<int>(), ToPose(t[2], name_ + ".loop_closures()")});
      }
    });
    return closures;
  }
  slam::EstimatorView View() const override {
    slam::EstimatorView view;
    Call("particles", [&] {
      if (!py::hasattr(object_, "particles")) return;
      // (N, 4) rows of x, y, yaw, weight.
      const auto rows = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
          object_.attr("particles")());
      if (!rows || rows.ndim() != 2 || rows.shape(1) != 4) return;
      const auto r = rows.unchecked<2>();
      for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
        view.particles.push_back({Pose2(r(i, 0), r(i, 1), r(i, 2)), r(i, 3)});
      }
    });
    return view;
  }

 private:
  // Runs `body` under the GIL. On the command line a Python exception becomes one line naming
  // the estimator and the method; called from Python it passes through with its traceback.
  template <typename F>
  void Call(const char* method, F&& body) const {
    py::gil_scoped_acquire gil;
    try {
      body();
    } catch (py::error_already_set& e) {
      if (!embedded_) throw;
      throw std::runtime_error(name_ + "." + method + "(): " + OneLine(e));
    } catch (const py::cast_error& e) {
      throw std::runtime_error(name_ + "." + method + "(): returned the wrong type: " + e.what());
    }
  }

  py::object object_;
  std::string name_;
  bool embedded_;
  bool has_record_ = false;
  bool has_record_estimate_ = false;
  mutable OccupancyGrid map_{OccupancyGridOptions{}};
};

// Whether calling `callable` accepts the keyword `name` (a parameter of that name or **kwargs).
bool AcceptsKeyword(const py::object& callable, const char* name) {
  try {
    const py::object parameters =
        py::module_::import("inspect").attr("signature")(callable).attr("parameters");
    if (parameters.contains(name)) return true;
    for (const auto& p : parameters.attr("values")()) {
      if (p.attr("kind").equal(p.attr("VAR_KEYWORD"))) return true;
    }
  } catch (py::error_already_set&) {
  }
  return false;
}

}  // namespace

OccupancyGrid GridFromLogOdds(py::handle array, const std::vector<double>& origin,
                              double resolution, const std::string& where) {
  const auto log_odds =
      py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!log_odds || log_odds.ndim() != 2) {
    throw std::runtime_error(where + ": log_odds must be a 2-D array (rows are y, columns x)");
  }
  if (origin.size() != 2) throw std::runtime_error(where + ": origin must be (x0, y0)");
  OccupancyGridOptions options;
  options.resolution_m = resolution;
  if (!(resolution > 0.0)) throw std::runtime_error(where + ": resolution must be > 0");
  const int height = static_cast<int>(log_odds.shape(0));
  const int width = static_cast<int>(log_odds.shape(1));
  OccupancyGrid grid(options, {origin[0], origin[1]}, width, height);
  const auto cells = log_odds.unchecked<2>();
  for (int iy = 0; iy < height; ++iy) {
    for (int ix = 0; ix < width; ++ix) grid.Set({ix, iy}, cells(iy, ix));
  }
  return grid;
}

slam::PythonEstimatorOptions OptionsForObject(py::object object, py::dict kwargs) {
  slam::PythonEstimatorOptions options;
  options.object = std::shared_ptr<void>(new py::object(std::move(object)), [](void* p) {
    py::gil_scoped_acquire gil;
    delete static_cast<py::object*>(p);
  });
  const py::object& held = *static_cast<py::object*>(options.object.get());
  // Named by the class (or the instance's class), as a scenario file would name it.
  const py::handle named =
      py::isinstance<py::type>(held) ? py::handle(held) : py::type::handle_of(held);
  options.module = py::str(named.attr("__module__"));
  options.class_name = py::str(named.attr("__qualname__"));
  for (const auto& [k, v] : kwargs) {
    const std::string key = py::str(k);
    if (py::isinstance<py::bool_>(v)) {
      options.options.emplace_back(key, v.cast<bool>());
    } else if (py::isinstance<py::int_>(v)) {
      options.options.emplace_back(key, v.cast<std::int64_t>());
    } else if (py::isinstance<py::float_>(v)) {
      options.options.emplace_back(key, v.cast<double>());
    } else if (py::isinstance<py::str>(v)) {
      options.options.emplace_back(key, v.cast<std::string>());
    } else {
      throw ConfigError(key + ": a python estimator's option is a number, a bool or a text");
    }
  }
  return options;
}

std::unique_ptr<slam::Estimator> MakePythonEstimator(const slam::PythonEstimatorOptions& options,
                                                     const slam::EstimatorContext& context,
                                                     bool embedded) {
  py::gil_scoped_acquire gil;
  py::object target;
  const std::string name = options.module + "." + options.class_name;
  if (options.object) {
    target = *static_cast<const py::object*>(options.object.get());
  } else {
    try {
      if (!options.path.empty()) {
        py::list path = py::module_::import("sys").attr("path");
        if (!path.contains(options.path)) path.insert(0, options.path);
      }
    } catch (py::error_already_set& e) {
      throw ConfigError("path: " + OneLine(e));
    }
    py::module_ module;
    try {
      module = py::module_::import(options.module.c_str());
    } catch (py::error_already_set& e) {
      throw ConfigError("module: cannot import '" + options.module + "' (from " +
                        (options.path.empty() ? std::string("sys.path") : options.path) +
                        " and PYTHONPATH): " + OneLine(e));
    }
    if (!py::hasattr(module, options.class_name.c_str())) {
      throw ConfigError("class: module '" + options.module + "' has no '" + options.class_name +
                        "'");
    }
    target = module.attr(options.class_name.c_str());
  }

  py::object instance = target;
  // A class or a factory is called; an object that already estimates is used as it is.
  if (py::isinstance<py::type>(target) || !py::hasattr(target, "add_scan")) {
    py::dict kwargs;
    for (const auto& option : options.options) {
      std::visit([&](const auto& v) { kwargs[py::str(option.first)] = py::cast(v); },
                 option.second);
    }
    if (AcceptsKeyword(target, "seed") && !kwargs.contains("seed")) kwargs["seed"] = context.seed;
    if (AcceptsKeyword(target, "robot") && !kwargs.contains("robot")) {
      kwargs["robot"] = py::cast(context.robot);
    }
    try {
      instance = target(**kwargs);
    } catch (py::error_already_set& e) {
      if (!embedded) throw;
      throw ConfigError(name + "(...): " + OneLine(e));
    }
  }
  return std::make_unique<PythonEstimator>(std::move(instance), name, embedded);
}

}  // namespace slamrig::python
