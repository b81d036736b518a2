// slamrig._core: the bench's C++ types and functions for Python. Arrays cross without copies
// where the C++ object owning the buffer can be kept alive (python/arrays.h); the few copies
// are said in the docstrings.

#include "python/core.h"

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "python/arrays.h"
#include "python/python_estimator.h"
#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world_yaml.h"
#include "slam/config/yaml_node.h"
#include "slam/eval/loop_closure_score.h"
#include "slam/eval/map_score.h"
#include "slam/eval/trajectory_metrics.h"
#include "slam/fusion/consistency.h"
#include "slam/io/log_reader.h"
#include "slam/pipeline/estimator_config.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/pipeline/python_estimator.h"
#include "slam/types/error.h"
#include "slam/types/random_stream.h"

namespace slamrig::python {
namespace {

using slam::Dataset;
using slam::EstimatorConfig;
using slam::EstimatorRun;
using slam::ScanEstimate;
using slam::SyncedScan;

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

// A scenario result with the spec it points at.
struct ScenarioRun {
  std::shared_ptr<scenario::ScenarioSpec> spec;
  scenario::ScenarioResult result;
};

}  // namespace

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

  // --- types -----------------------------------------------------------------------------------
  py::class_<Pose2>(m, "Pose2", "A rigid transform in SE(2) (a_from_b); theta in (-pi, pi].")
      .def(py::init<>())
      .def(py::init<double, double, double>(), py::arg("x"), py::arg("y"), py::arg("theta"))
      .def_property_readonly("x", &Pose2::x)
      .def_property_readonly("y", &Pose2::y)
      .def_property_readonly("theta", &Pose2::theta)
      .def("inverse", &Pose2::Inverse)
      .def("between", &Pose2::Between, py::arg("other"), "this^-1 * other")
      .def("__mul__", [](const Pose2& a, const Pose2& b) { return a * b; })
      .def("__eq__", [](const Pose2& a, const Pose2& b) { return a == b; })
      .def("__iter__",
           [](const Pose2& p) { return py::iter(py::make_tuple(p.x(), p.y(), p.theta())); })
      .def("__repr__", [](const Pose2& p) {
        return "Pose2(" + py::repr(py::float_(p.x())).cast<std::string>() + ", " +
               py::repr(py::float_(p.y())).cast<std::string>() + ", " +
               py::repr(py::float_(p.theta())).cast<std::string>() + ")";
      });

  py::class_<LaserScan>(m, "LaserScan",
                        "One lidar sweep (REP-117). `ranges` views the scan's own buffer.")
      .def(py::init([](std::int64_t time_ns, double angle_min, double angle_increment,
                       py::array_t<float, py::array::c_style | py::array::forcecast> ranges,
                       double range_min, double range_max, double time_increment,
                       const Pose2& base_from_laser) {
             LaserScan s;
             s.time = Time::FromNanoseconds(time_ns);
             s.angle_min_rad = angle_min;
             s.angle_increment_rad = angle_increment;
             s.ranges_m.assign(ranges.data(), ranges.data() + ranges.size());
             s.range_min_m = range_min;
             s.range_max_m = range_max;
             s.time_increment_s = time_increment;
             s.base_from_laser = base_from_laser;
             return s;
           }),
           py::arg("time_ns"), py::arg("angle_min"), py::arg("angle_increment"), py::arg("ranges"),
           py::arg("range_min") = 0.0, py::arg("range_max") = 30.0, py::arg("time_increment") = 0.0,
           py::arg("base_from_laser") = Pose2())
      .def_property_readonly("time_ns", [](const LaserScan& s) { return s.time.ns; })
      .def_property_readonly("time", [](const LaserScan& s) { return s.time.seconds(); })
      .def_readonly("angle_min", &LaserScan::angle_min_rad)
      .def_readonly("angle_increment", &LaserScan::angle_increment_rad)
      .def_readonly("time_increment", &LaserScan::time_increment_s)
      .def_readonly("range_min", &LaserScan::range_min_m)
      .def_readonly("range_max", &LaserScan::range_max_m)
      .def_readonly("base_from_laser", &LaserScan::base_from_laser)
      .def_property_readonly(
          "ranges",
          [](py::object self) {
            const auto& s = self.cast<const LaserScan&>();
            return View1(s.ranges_m.data(), s.ranges_m.size(), self);
          },
          "float32 ranges in metres, a read-only view of the scan (no copy)")
      .def_property_readonly(
          "angles",
          [](const LaserScan& s) {
            py::array_t<double> a(static_cast<py::ssize_t>(s.ranges_m.size()));
            auto w = a.mutable_unchecked<1>();
            for (std::size_t i = 0; i < s.ranges_m.size(); ++i) w(i) = s.BeamAngle(i);
            return a;
          },
          "beam angles in the laser frame (computed, a new array)")
      .def_property_readonly(
          "hits",
          [](const LaserScan& s) {
            py::array_t<bool> a(static_cast<py::ssize_t>(s.ranges_m.size()));
            auto w = a.mutable_unchecked<1>();
            for (std::size_t i = 0; i < s.ranges_m.size(); ++i) w(i) = s.IsHit(i);
            return a;
          },
          "True where a beam is a real return (range_min <= r < range_max)")
      .def("__repr__", [](const LaserScan& s) {
        return "LaserScan(t=" + std::to_string(s.time.seconds()) + ", " +
               std::to_string(s.ranges_m.size()) + " beams)";
      });

  py::class_<OdometryPose>(m, "OdometryPose", "A pose of the platform's own odometry.")
      .def(py::init([](std::int64_t time_ns, const Pose2& pose) {
             return OdometryPose{Time::FromNanoseconds(time_ns), pose};
           }),
           py::arg("time_ns"), py::arg("odom_from_base"))
      .def_property_readonly("time_ns", [](const OdometryPose& r) { return r.time.ns; })
      .def_property_readonly("time", [](const OdometryPose& r) { return r.time.seconds(); })
      .def_readonly("odom_from_base", &OdometryPose::odom_from_base);

  py::class_<WheelTicks>(m, "WheelTicks", "Encoder tick increments per wheel.")
      .def(py::init([](std::int64_t time_ns, std::vector<std::int32_t> right,
                       std::vector<std::int32_t> left) {
             return WheelTicks{Time::FromNanoseconds(time_ns), std::move(right), std::move(left)};
           }),
           py::arg("time_ns"), py::arg("right_ticks"), py::arg("left_ticks"))
      .def_property_readonly("time_ns", [](const WheelTicks& r) { return r.time.ns; })
      .def_property_readonly("time", [](const WheelTicks& r) { return r.time.seconds(); })
      .def_property_readonly("right_ticks",
                             [](py::object self) {
                               const auto& r = self.cast<const WheelTicks&>();
                               return View1(r.right_ticks.data(), r.right_ticks.size(), self);
                             })
      .def_property_readonly("left_ticks", [](py::object self) {
        const auto& r = self.cast<const WheelTicks&>();
        return View1(r.left_ticks.data(), r.left_ticks.size(), self);
      });

  py::class_<ImuSample>(m, "ImuSample", "One IMU sample: rad/s and m/s^2 (gravity included).")
      .def(py::init([](std::int64_t time_ns, const Eigen::Vector3d& w, const Eigen::Vector3d& a) {
             return ImuSample{Time::FromNanoseconds(time_ns), w, a};
           }),
           py::arg("time_ns"), py::arg("angular_velocity"), py::arg("linear_acceleration"))
      .def_property_readonly("time_ns", [](const ImuSample& r) { return r.time.ns; })
      .def_property_readonly("time", [](const ImuSample& r) { return r.time.seconds(); })
      .def_property_readonly(
          "angular_velocity",
          [](py::object self) {
            return View1(self.cast<const ImuSample&>().angular_velocity_rad_s.data(), 3, self);
          })
      .def_property_readonly("linear_acceleration", [](py::object self) {
        return View1(self.cast<const ImuSample&>().linear_acceleration_m_s2.data(), 3, self);
      });

  py::class_<Trajectory>(m, "Trajectory",
                         "Stamped poses. `poses` (N, 3) and `stamps_ns` (N,) view its buffer.")
      .def(py::init([](py::handle rows) { return ToTrajectory(rows); }), py::arg("rows"),
           "From an (N, 4) array of t [s], x, y, yaw.")
      .def("__len__", &Trajectory::size)
      .def_property_readonly(
          "poses",
          [](py::object self) { return PoseView(self.cast<const Trajectory&>().poses(), self); })
      .def_property_readonly(
          "stamps_ns",
          [](py::object self) { return StampView(self.cast<const Trajectory&>().poses(), self); })
      .def_property_readonly(
          "times",
          [](const Trajectory& t) {
            py::array_t<double> a(static_cast<py::ssize_t>(t.size()));
            auto w = a.mutable_unchecked<1>();
            for (std::size_t i = 0; i < t.size(); ++i) w(i) = t[i].time.seconds();
            return a;
          },
          "stamps in seconds (computed, a new array)")
      .def("interpolate", [](const Trajectory& t,
                             double time_s) { return t.Interpolate(Time::FromSeconds(time_s)); })
      .def("path_length", &Trajectory::PathLength);

  py::class_<slam::DiffDriveParams>(m, "DiffDriveParams", "Wheel geometry for encoder ticks.")
      .def(py::init<>())
      .def_readwrite("wheel_radius_m", &slam::DiffDriveParams::wheel_radius_m)
      .def_readwrite("ticks_per_revolution", &slam::DiffDriveParams::ticks_per_revolution)
      .def_readwrite("track_width_m", &slam::DiffDriveParams::track_width_m);

  py::class_<OccupancyGrid>(m, "OccupancyGrid",
                            "A log-odds grid; `log_odds` is an (H, W) view, row 0 at the lowest y.")
      .def(py::init([](double resolution) {
             OccupancyGridOptions o;
             o.resolution_m = resolution;
             for (const auto& e : o.Validate()) throw ConfigError(e);
             return OccupancyGrid(o);
           }),
           py::arg("resolution") = 0.05)
      .def_static(
          "from_log_odds",
          [](py::array log_odds, std::vector<double> origin, double resolution) {
            return GridFromLogOdds(log_odds, origin, resolution, "OccupancyGrid.from_log_odds");
          },
          py::arg("log_odds"), py::arg("origin"), py::arg("resolution"))
      .def_property_readonly("resolution", &OccupancyGrid::resolution)
      .def_property_readonly(
          "origin",
          [](const OccupancyGrid& g) { return py::make_tuple(g.origin().x(), g.origin().y()); })
      .def_property_readonly("width", &OccupancyGrid::width)
      .def_property_readonly("height", &OccupancyGrid::height)
      .def_property_readonly(
          "log_odds",
          [](py::object self) {
            const auto& g = self.cast<const OccupancyGrid&>();
            return View(g.log_odds().data(), {g.height(), g.width()},
                        {static_cast<py::ssize_t>(g.width() * sizeof(float)), sizeof(float)}, self);
          },
          "(H, W) float32, read-only view; invalid after the grid grows (insert_scan)")
      .def(
          "probability",
          [](const OccupancyGrid& g) {
            py::array_t<double> a({g.height(), g.width()});
            auto w = a.mutable_unchecked<2>();
            for (int iy = 0; iy < g.height(); ++iy) {
              for (int ix = 0; ix < g.width(); ++ix) w(iy, ix) = g.Probability({ix, iy});
            }
            return a;
          },
          "occupancy probability per cell (computed, a new array)")
      .def("insert_scan", &OccupancyGrid::InsertScan, py::arg("scan"), py::arg("world_from_base"));

  // --- logs ------------------------------------------------------------------------------------
  py::class_<Dataset, std::shared_ptr<Dataset>>(
      m, "Dataset",
      "A log's records in time order (iterate, index) and its reference on its own channel.")
      .def("__len__", [](const Dataset& d) { return d.records.size(); })
      .def("__getitem__",
           [](py::object self, py::ssize_t i) {
             const auto& d = self.cast<const Dataset&>();
             const auto n = static_cast<py::ssize_t>(d.records.size());
             if (i < 0) i += n;
             if (i < 0 || i >= n) throw py::index_error("record index out of range");
             return RecordRef(d.records[static_cast<std::size_t>(i)], self);
           })
      .def("__iter__",
           [](py::object self) {
             py::list records;
             for (const Record& r : self.cast<const Dataset&>().records) {
               records.append(RecordRef(r, self));
             }
             return py::iter(records);
           })
      .def(
          "scans",
          [](py::object self) {
            py::list scans;
            for (const Record& r : self.cast<const Dataset&>().records) {
              if (const auto* s = std::get_if<LaserScan>(&r)) {
                scans.append(py::cast(s, py::return_value_policy::reference_internal, self));
              }
            }
            return scans;
          },
          "the laser scans, each viewing the dataset's buffers")
      .def(
          "scan_ranges",
          [](const Dataset& d) {
            std::vector<const LaserScan*> scans;
            for (const Record& r : d.records) {
              if (const auto* s = std::get_if<LaserScan>(&r)) scans.push_back(s);
            }
            const std::size_t beams = scans.empty() ? 0 : scans.front()->ranges_m.size();
            for (const auto* s : scans) {
              if (s->ranges_m.size() != beams)
                throw py::value_error("scans have different beam counts; use scans()");
            }
            py::array_t<float> a(
                {static_cast<py::ssize_t>(scans.size()), static_cast<py::ssize_t>(beams)});
            float* out = a.mutable_data();
            for (const auto* s : scans)
              out = std::copy(s->ranges_m.begin(), s->ranges_m.end(), out);
            return a;
          },
          "every scan's ranges as one (scans, beams) float32 array: one copy, since each scan "
          "owns its own buffer")
      .def_property_readonly(
          "reference_stamps_ns",
          [](py::object self) { return StampView(self.cast<const Dataset&>().reference, self); })
      .def_property_readonly(
          "reference_poses",
          [](py::object self) { return PoseView(self.cast<const Dataset&>().reference, self); },
          "(N, 3) x, y, yaw of the reference, a view (no copy)")
      .def_readonly("source", &Dataset::source)
      .def_readonly("format", &Dataset::format)
      .def_readonly("reference_kind", &Dataset::reference_kind)
      .def_readonly("notes", &Dataset::notes);

  m.def(
      "read_log",
      [](const std::string& path, bool lenient) {
        slam::LogReadOptions options;
        options.lenient = lenient;
        py::gil_scoped_release release;
        return std::make_shared<Dataset>(slam::ReadLog(slam::ResolveLogPath(path), options));
      },
      py::arg("path"), py::arg("lenient") = false,
      "Reads any log slamrig reads (CARMEN, ECE276A, ROS 2 bag); relative paths also in "
      "SLAMRIG_DATA_DIR. Errors are ParseError with file, line and field.");
  m.def("data_dir", &slam::DataDir);

  // --- simulator -------------------------------------------------------------------------------
  py::class_<sim::TruthSample>(m, "TruthSample", "Ground truth at one record's time.")
      .def_property_readonly("time_ns", [](const sim::TruthSample& t) { return t.time.ns; })
      .def_property_readonly("time", [](const sim::TruthSample& t) { return t.time.seconds(); })
      .def_readonly("map_from_base", &sim::TruthSample::map_from_base)
      .def_readonly("velocity", &sim::TruthSample::velocity_m_s)
      .def_readonly("yaw_rate", &sim::TruthSample::yaw_rate_rad_s)
      .def_property_readonly("true_ranges", [](py::object self) {
        const auto& t = self.cast<const sim::TruthSample&>();
        return View1(t.true_ranges_m.data(), t.true_ranges_m.size(), self);
      });

  py::class_<sim::StepResult, std::shared_ptr<sim::StepResult>>(
      m, "StepResult", "What one physics step released: records and, separately, their truth.")
      .def_property_readonly("time", [](const sim::StepResult& s) { return s.time.seconds(); })
      .def_property_readonly("time_ns", [](const sim::StepResult& s) { return s.time.ns; })
      .def_property_readonly("records",
                             [](py::object self) {
                               py::list records;
                               for (const Record& r : self.cast<const sim::StepResult&>().records)
                                 records.append(RecordRef(r, self));
                               return records;
                             })
      .def_property_readonly(
          "truth",
          [](py::object self) {
            py::list truth;
            for (const auto& t : self.cast<const sim::StepResult&>().truth) {
              truth.append(py::cast(&t, py::return_value_policy::reference_internal, self));
            }
            return truth;
          })
      .def("__len__", [](const sim::StepResult& s) { return s.records.size(); });

  py::class_<sim::Simulator>(m, "Simulator", "A headless simulated run on its own clock.")
      .def(py::init([](const std::string& world, const std::string& robot, std::uint64_t seed,
                       double physics_rate_hz, bool no_noise, int laps) {
             sim::SimulatorOptions options;
             options.world = sim::LoadWorldSpec(sim::FindPresetFile(world, "worlds"));
             options.robot = sim::LoadRobotSpec(sim::FindPresetFile(robot, "robots"));
             if (no_noise) options.robot = sim::WithoutNoise(options.robot);
             options.seed = seed;
             options.physics_rate_hz = physics_rate_hz;
             if (laps != 0) options.world.drive.laps = laps;
             for (const std::string& e : options.Validate()) throw ConfigError(e);
             return std::make_unique<sim::Simulator>(options);
           }),
           py::arg("world") = "office", py::arg("robot") = "ece276a", py::arg("seed") = 1,
           py::arg("physics_rate_hz") = 200.0, py::arg("no_noise") = false, py::arg("laps") = 0,
           "World and robot as files or preset names, as `slamrig simulate` takes them.")
      .def(
          "step", [](sim::Simulator& s) { return std::make_shared<sim::StepResult>(s.Step()); },
          "Advances one physics step; the records it released.")
      .def(
          "run",
          [](sim::Simulator& s, double until_s) {
            std::vector<std::shared_ptr<sim::StepResult>> steps;
            {
              py::gil_scoped_release release;
              while (s.time().seconds() < until_s - 0.5 * s.step_s()) {
                auto step = std::make_shared<sim::StepResult>(s.Step());
                if (!step->records.empty()) steps.push_back(std::move(step));
              }
            }
            return steps;
          },
          py::arg("until_s"), "Steps until `until_s`; the steps that released records.")
      .def("flush", [](sim::Simulator& s) { return std::make_shared<sim::StepResult>(s.Flush()); })
      .def("teleport", &sim::Simulator::Teleport, py::arg("map_from_base"))
      .def(
          "set_command",
          [](sim::Simulator& s, std::optional<std::pair<double, double>> command) {
            if (command) {
              s.SetCommandOverride(sim::VelocityCommand{command->first, command->second});
            } else {
              s.SetCommandOverride(std::nullopt);
            }
          },
          py::arg("command"), "(v m/s, omega rad/s) instead of the world's driver; None: back")
      .def("truth", &sim::Simulator::Truth)
      .def_property_readonly("time", [](const sim::Simulator& s) { return s.time().seconds(); })
      .def_property_readonly("time_ns", [](const sim::Simulator& s) { return s.time().ns; })
      .def_property_readonly("step_s", &sim::Simulator::step_s)
      .def_property_readonly("drive_finished", &sim::Simulator::drive_finished);

  // --- estimators ------------------------------------------------------------------------------
  py::class_<ScanEstimate>(m, "ScanEstimate", "What an estimator says about one scan.")
      .def(py::init([](const Pose2& pose, std::optional<Pose2> mean_pose,
                       std::map<std::string, double> trace,
                       std::optional<Eigen::Matrix3d> covariance) {
             ScanEstimate e;
             e.pose = pose;
             e.mean_pose = mean_pose;
             for (const auto& [k, v] : trace) e.trace.push_back({k, v});
             e.covariance = covariance;
             return e;
           }),
           py::arg("pose"), py::arg("mean_pose") = std::nullopt,
           py::arg("trace") = std::map<std::string, double>{}, py::arg("covariance") = std::nullopt)
      .def_readonly("pose", &ScanEstimate::pose)
      .def_readonly("mean_pose", &ScanEstimate::mean_pose)
      .def_property_readonly("trace",
                             [](const ScanEstimate& e) {
                               py::dict d;
                               for (const auto& t : e.trace) d[py::str(t.name)] = t.value;
                               return d;
                             })
      .def_readonly("covariance", &ScanEstimate::covariance);

  py::class_<SyncedScan, std::shared_ptr<SyncedScan>>(
      m, "SyncedScan", "A scan with the odometry synchronised to its time.")
      .def_property_readonly("scan",
                             [](py::object self) {
                               return py::cast(&self.cast<const SyncedScan&>().scan,
                                               py::return_value_policy::reference_internal, self);
                             })
      .def_readonly("odom_from_base", &SyncedScan::odom_from_base)
      .def_readonly("increment", &SyncedScan::increment)
      .def_readonly("dt", &SyncedScan::dt_s)
      .def_readonly("distance", &SyncedScan::distance_m)
      .def_readonly("yaw_change", &SyncedScan::yaw_change_rad)
      .def_readonly("imu_samples", &SyncedScan::imu_samples);

  py::enum_<slam::OdometrySource>(m, "OdometrySource")
      .value("auto", slam::OdometrySource::kAuto)
      .value("wheel_ticks", slam::OdometrySource::kWheelTicks)
      .value("poses", slam::OdometrySource::kOdometryPoses)
      .value("none", slam::OdometrySource::kNone);

  py::class_<slam::ScanSynchronizer>(m, "ScanSynchronizer",
                                     "Turns records into synchronised scans, one at a time.")
      .def(py::init([](const EstimatorConfig& config, slam::OdometrySource source) {
             return std::make_unique<slam::ScanSynchronizer>(config.odometry, source);
           }),
           py::arg("config"), py::arg("source"))
      .def(
          "add",
          [](slam::ScanSynchronizer& s, py::handle record) {
            std::vector<std::shared_ptr<SyncedScan>> out;
            for (auto& scan : s.Add(ToRecord(record)))
              out.push_back(std::make_shared<SyncedScan>(std::move(scan)));
            return out;
          },
          py::arg("record"))
      .def("flush", [](slam::ScanSynchronizer& s) {
        std::vector<std::shared_ptr<SyncedScan>> out;
        for (auto& scan : s.Flush()) out.push_back(std::make_shared<SyncedScan>(std::move(scan)));
        return out;
      });

  m.def(
      "resolve_odometry_source",
      [](const Dataset& d, slam::OdometrySource wanted) {
        return slam::ResolveOdometrySource(d.records, wanted);
      },
      py::arg("dataset"), py::arg("wanted") = slam::OdometrySource::kAuto);
  m.def(
      "estimator_seed",
      [](std::uint64_t run_seed, const std::string& name) {
        return RandomStream(run_seed, "slam." + name).NextU64();
      },
      py::arg("run_seed"), py::arg("name"),
      "The seed a configuration `name` gets in a run seeded `run_seed` (the stream "
      "slam.<name>): what a Python estimator's `seed` keyword receives.");
  m.def("algorithm_names", [] {
    std::vector<std::string> names;
    for (const auto& a : slam::Algorithms()) names.push_back(a.name);
    return names;
  });

  py::class_<EstimatorConfig>(m, "EstimatorConfig",
                              "One named SLAM configuration: algorithm, options, odometry.")
      .def(py::init([](const std::string& name, const std::string& algorithm, py::kwargs kwargs) {
             return MakeConfig(name, algorithm, kwargs);
           }),
           py::arg("name"), py::arg("algorithm") = "pf",
           "Keyword options as a scenario's `slam:` entry takes them (particles=30, "
           "odometry={'source': 'poses'}, preset='reports'); checked strictly.")
      .def_static(
          "python",
          [](const std::string& name, py::object estimator, py::kwargs kwargs) {
            EstimatorConfig config = slam::DefaultEstimatorConfig(name, "python");
            static_cast<slam::PythonAlgorithmOptions&>(*config.options).options() =
                OptionsForObject(std::move(estimator), kwargs);
            return config;
          },
          py::arg("name"), py::arg("estimator"),
          "A configuration running `estimator` (a class, a factory or an instance) with the "
          "keyword options passed to it.")
      .def_readonly("name", &EstimatorConfig::name)
      .def_readonly("algorithm", &EstimatorConfig::algorithm)
      .def_readonly("preset", &EstimatorConfig::preset)
      .def_property(
          "robot", [](const EstimatorConfig& c) { return c.odometry.robot; },
          [](EstimatorConfig& c, const slam::DiffDriveParams& p) { c.odometry.robot = p; })
      .def("to_yaml", [](const EstimatorConfig& c) {
        YAML::Emitter out;
        slam::WriteEstimatorConfig(c, &out);
        return std::string(out.c_str());
      });

  py::class_<slam::Estimator>(m, "Estimator",
                              "A built-in (or Python) estimator behind the C++ interface.")
      .def(py::init([](const EstimatorConfig& config, std::uint64_t run_seed) {
             return slam::MakeEstimator(config, run_seed);
           }),
           py::arg("config"), py::arg("run_seed") = 1)
      .def(
          "add_record", [](slam::Estimator& e, py::handle r) { e.AddRecord(ToRecord(r)); },
          py::arg("record"))
      .def("record_estimate", &slam::Estimator::RecordEstimate)
      .def("add_scan", &slam::Estimator::AddScan, py::arg("scan"))
      .def("finish", &slam::Estimator::Finish)
      .def("revised_poses", &slam::Estimator::RevisedPoses)
      .def(
          "map", [](const slam::Estimator& e) { return OccupancyGrid(e.map()); },
          "a copy of the map as it is now (the estimator keeps changing its own)")
      .def("statistics", &slam::Estimator::Statistics)
      .def("loop_closures",
           [](const slam::Estimator& e) {
             py::list out;
             for (const auto& c : e.LoopClosures())
               out.append(py::make_tuple(c.from_scan, c.to_scan, c.measurement));
             return out;
           })
      .def("particles", [](const slam::Estimator& e) {
        const auto view = e.View();
        py::array_t<double> a({static_cast<py::ssize_t>(view.particles.size()), py::ssize_t{4}});
        auto w = a.mutable_unchecked<2>();
        for (std::size_t i = 0; i < view.particles.size(); ++i) {
          const auto& p = view.particles[i];
          w(i, 0) = p.pose.x();
          w(i, 1) = p.pose.y();
          w(i, 2) = p.pose.theta();
          w(i, 3) = p.weight;
        }
        return a;
      });

  py::class_<EstimatorRun, std::shared_ptr<EstimatorRun>>(
      m, "EstimatorRun", "What one estimator produced over a run, in its own frame.")
      .def_readonly("name", &EstimatorRun::name)
      .def_readonly("algorithm", &EstimatorRun::algorithm)
      .def_readonly("online", &EstimatorRun::online)
      .def_readonly("final", &EstimatorRun::final)
      .def_readonly("mean", &EstimatorRun::mean)
      .def_readonly("record_rate", &EstimatorRun::record_rate)
      .def_readonly("map", &EstimatorRun::map)
      .def_readonly("statistics", &EstimatorRun::statistics)
      .def_readonly("traces", &EstimatorRun::traces)
      .def_readonly("trace_time_s", &EstimatorRun::trace_time_s)
      .def_property_readonly(
          "covariances",
          [](const EstimatorRun& r) {
            py::array_t<double> a(
                {static_cast<py::ssize_t>(r.covariances.size()), py::ssize_t{3}, py::ssize_t{3}});
            auto w = a.mutable_unchecked<3>();
            for (std::size_t k = 0; k < r.covariances.size(); ++k)
              for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) w(k, i, j) = r.covariances[k](i, j);
            return a;
          })
      .def_readonly("wall_s", &EstimatorRun::wall_s);

  py::class_<slam::EstimatorRunner>(
      m, "EstimatorRunner",
      "Feeds records one at a time through a ScanSynchronizer into one estimator.")
      .def(py::init<const EstimatorConfig&, slam::OdometrySource, std::uint64_t>(),
           py::arg("config"), py::arg("source"), py::arg("run_seed") = 1)
      .def(
          "add", [](slam::EstimatorRunner& r, py::handle record) { r.Add(ToRecord(record)); },
          py::arg("record"))
      .def("finish", &slam::EstimatorRunner::Finish)
      .def("scans", &slam::EstimatorRunner::scans)
      .def("pose", &slam::EstimatorRunner::pose)
      .def("take_result",
           [](slam::EstimatorRunner& r) { return std::make_shared<EstimatorRun>(r.TakeResult()); });

  m.def(
      "run_estimator",
      [](EstimatorConfig config, const Dataset& dataset, std::uint64_t run_seed,
         std::size_t max_scans) {
        if (config.odometry.source == slam::OdometrySource::kAuto) {
          config.odometry.source =
              slam::ResolveOdometrySource(dataset.records, config.odometry.source);
        }
        slam::RunLimits limits;
        limits.max_scans = max_scans;
        py::gil_scoped_release release;
        return std::make_shared<EstimatorRun>(
            slam::RunEstimator(config, dataset.records, run_seed, limits));
      },
      py::arg("config"), py::arg("dataset"), py::arg("run_seed") = 1, py::arg("max_scans") = 0,
      "Runs `config` over a whole log, exactly as `slamrig slam` does.");

  // --- evaluation ------------------------------------------------------------------------------
  m.def(
      "ate",
      [](py::handle estimate, py::handle reference) {
        const auto r = slam::ComputeAte(ToTrajectory(estimate), ToTrajectory(reference));
        py::dict d;
        d["translation"] = StatsDict(r.translation_m);
        d["rotation"] = StatsDict(r.rotation_rad);
        d["reference_from_estimate"] = r.reference_from_estimate;
        return d;
      },
      py::arg("estimate"), py::arg("reference"),
      "ATE after SE(2) alignment; trajectories as Trajectory or (N, 4) t, x, y, yaw arrays.");
  m.def(
      "rpe",
      [](py::handle estimate, py::handle reference, double distance_m) {
        const auto r =
            slam::ComputeRpe(ToTrajectory(estimate), ToTrajectory(reference), distance_m);
        py::dict d;
        d["distance_m"] = r.distance_m;
        d["translation"] = StatsDict(r.translation_m);
        d["rotation"] = StatsDict(r.rotation_rad);
        return d;
      },
      py::arg("estimate"), py::arg("reference"), py::arg("distance_m") = 0.0,
      "RPE over pose pairs `distance_m` apart along the reference (0: consecutive poses).");
  m.def(
      "score_map",
      [](const OccupancyGrid& estimate, const OccupancyGrid& truth,
         const Pose2& truth_from_estimate, int tolerance_cells, double occupied_probability) {
        slam::MapScoreOptions options;
        options.tolerance_cells = tolerance_cells;
        options.occupied_probability = occupied_probability;
        for (const auto& e : options.Validate()) throw ConfigError(e);
        const auto s = slam::ScoreMap(estimate, truth_from_estimate, truth, options);
        py::dict d;
        d["precision"] = s.precision;
        d["recall"] = s.recall;
        d["f1"] = s.f1;
        d["iou"] = s.iou;
        d["estimate_occupied"] = s.estimate_occupied;
        d["truth_occupied"] = s.truth_occupied;
        return d;
      },
      py::arg("estimate"), py::arg("truth"), py::arg("truth_from_estimate") = Pose2(),
      py::arg("tolerance_cells") = 1, py::arg("occupied_probability") = 0.65);
  m.def(
      "score_loop_closures",
      [](const std::vector<std::tuple<int, int, Pose2>>& closures, py::handle reference) {
        std::vector<slam::LoopClosure> c;
        for (const auto& [from, to, z] : closures) c.push_back({from, to, z});
        std::vector<Pose2> poses;
        const Trajectory trajectory = ToTrajectory(reference);
        for (const auto& p : trajectory.poses()) poses.push_back(p.pose);
        const auto s = slam::ScoreLoopClosures(c, poses);
        py::dict d;
        d["closures"] = s.closures;
        d["false_closures"] = s.false_closures;
        d["precision"] = s.precision;
        d["recall"] = s.recall;
        d["revisit_episodes"] = s.revisit_episodes;
        d["is_true"] = s.is_true;
        return d;
      },
      py::arg("closures"), py::arg("reference"),
      "Precision and recall of (from_scan, to_scan, Pose2) closures against one reference "
      "pose per scan.");
  m.def(
      "nees",
      [](py::array_t<double, py::array::c_style | py::array::forcecast> truth,
         py::array_t<double, py::array::c_style | py::array::forcecast> estimate,
         py::array_t<double, py::array::c_style | py::array::forcecast> covariances) {
        if (truth.ndim() != 2 || truth.shape(1) != 3 || estimate.ndim() != 2 ||
            estimate.shape(0) != truth.shape(0) || estimate.shape(1) != 3 ||
            covariances.ndim() != 3 || covariances.shape(0) != truth.shape(0) ||
            covariances.shape(1) != 3 || covariances.shape(2) != 3) {
          throw py::value_error("nees: truth and estimate (N, 3), covariances (N, 3, 3)");
        }
        const auto t = truth.unchecked<2>();
        const auto e = estimate.unchecked<2>();
        const auto c = covariances.unchecked<3>();
        py::array_t<double> out(truth.shape(0));
        auto w = out.mutable_unchecked<1>();
        for (py::ssize_t k = 0; k < truth.shape(0); ++k) {
          Eigen::Matrix3d p;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) p(i, j) = c(k, i, j);
          w(k) =
              slam::PoseNees(Pose2(t(k, 0), t(k, 1), t(k, 2)), Pose2(e(k, 0), e(k, 1), e(k, 2)), p);
        }
        return out;
      },
      py::arg("truth"), py::arg("estimate"), py::arg("covariances"),
      "Pose NEES per row (x, y, yaw), same frame; inf where a covariance is singular.");
  m.def(
      "anees_bounds",
      [](int dimension, int runs) {
        const auto b = slam::AneesBounds(dimension, runs);
        return py::make_tuple(b.lower, b.upper);
      },
      py::arg("dimension"), py::arg("runs"), "Two-sided 95 % bounds of the average NEES.");

  // --- scenarios -------------------------------------------------------------------------------
  py::class_<scenario::ScenarioSpec, std::shared_ptr<scenario::ScenarioSpec>>(
      m, "ScenarioSpec", "A scenario read strictly from its file.")
      .def_readonly("path", &scenario::ScenarioSpec::path)
      .def_readonly("name", &scenario::ScenarioSpec::name)
      .def_readonly("description", &scenario::ScenarioSpec::description)
      .def_readonly("seed", &scenario::ScenarioSpec::seed)
      .def_readonly("duration_s", &scenario::ScenarioSpec::duration_s)
      .def_property_readonly("config_names",
                             [](const scenario::ScenarioSpec& s) {
                               std::vector<std::string> names;
                               for (const auto& c : s.configs) names.push_back(c.name);
                               return names;
                             })
      .def(
          "add_config",
          [](scenario::ScenarioSpec& s, const EstimatorConfig& config) {
            for (const auto& c : s.configs) {
              if (c.name == config.name)
                throw ConfigError("slam." + config.name + ": the scenario has this name already");
            }
            EstimatorConfig copy = config;
            // The source decides the wheel geometry, as for the file's own configurations.
            if (!s.configs.empty()) copy.odometry.robot = s.configs.front().odometry.robot;
            s.configs.push_back(std::move(copy));
          },
          py::arg("config"),
          "Adds a configuration (e.g. EstimatorConfig.python(...)) to run beside the file's.")
      .def_readonly("resolved_yaml", &scenario::ScenarioSpec::resolved_yaml);

  m.def(
      "load_scenario",
      [](const std::string& path, const std::vector<std::string>& overrides,
         std::optional<std::uint64_t> seed) {
        return std::make_shared<scenario::ScenarioSpec>(
            scenario::LoadScenario(scenario::FindScenarioFile(path), overrides, seed));
      },
      py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
      py::arg("seed") = std::nullopt,
      "A scenario file or shipped name; overrides as `--set` takes them. ConfigError names file, "
      "line and key.");

  py::class_<scenario::ConfigResult>(m, "ConfigResult", "One configuration's outputs and scores.")
      .def_readonly("name", &scenario::ConfigResult::name)
      .def_readonly("algorithm", &scenario::ConfigResult::algorithm)
      .def_readonly("estimate", &scenario::ConfigResult::estimate)
      .def_readonly("online", &scenario::ConfigResult::online)
      .def_readonly("mean_estimate", &scenario::ConfigResult::mean_estimate)
      .def_readonly("run", &scenario::ConfigResult::run)
      .def_readonly("map_from_estimator", &scenario::ConfigResult::map_from_estimator)
      .def_readonly("metrics", &scenario::ConfigResult::metrics)
      .def_readonly("nees", &scenario::ConfigResult::nees);

  py::class_<ScenarioRun, std::shared_ptr<ScenarioRun>>(m, "ScenarioResult",
                                                        "A finished scenario run.")
      .def_property_readonly("spec", [](const ScenarioRun& r) { return r.spec; })
      .def_property_readonly("passed", [](const ScenarioRun& r) { return r.result.passed; })
      .def_property_readonly("truth",
                             [](py::object self) {
                               return py::cast(&self.cast<const ScenarioRun&>().result.truth,
                                               py::return_value_policy::reference_internal, self);
                             })
      .def_property_readonly("truth_map", [](const ScenarioRun& r) { return r.result.truth_map; })
      .def_property_readonly("configs",
                             [](py::object self) {
                               py::dict d;
                               for (const auto& c : self.cast<const ScenarioRun&>().result.configs)
                                 d[py::str(c.name)] = py::cast(
                                     &c, py::return_value_policy::reference_internal, self);
                               return d;
                             })
      .def_property_readonly("sim_time_s", [](const ScenarioRun& r) { return r.result.sim_time_s; })
      .def_property_readonly("scans", [](const ScenarioRun& r) { return r.result.scans; })
      .def_property_readonly("scans_blacked_out",
                             [](const ScenarioRun& r) { return r.result.scans_blacked_out; })
      .def_property_readonly("notes", [](const ScenarioRun& r) { return r.result.notes; })
      .def_property_readonly("outcomes",
                             [](const ScenarioRun& r) {
                               py::list out;
                               for (const auto& o : r.result.outcomes) {
                                 py::dict d;
                                 d["config"] = o.expectation.config;
                                 d["metric"] = o.expectation.metric;
                                 d["is_max"] = o.expectation.is_max;
                                 d["threshold"] = o.expectation.threshold;
                                 d["value"] = o.value;
                                 d["passed"] = o.passed;
                                 d["description"] = o.Describe();
                                 out.append(d);
                               }
                               return out;
                             })
      .def(
          "write_report",
          [](const ScenarioRun& r, const std::string& out_dir) {
            py::gil_scoped_release release;
            scenario::WriteReport(r.result, out_dir);
          },
          py::arg("out_dir"))
      .def("expectation_table",
           [](const ScenarioRun& r) { return scenario::ExpectationTable(r.result); });

  m.def(
      "run_scenario",
      [](std::shared_ptr<scenario::ScenarioSpec> spec, bool view,
         std::function<void(double, double)> progress) {
        auto run = std::make_shared<ScenarioRun>();
        // The run keeps its own copy: later add_config calls do not change a finished result.
        run->spec = std::make_shared<scenario::ScenarioSpec>(*spec);
        scenario::RunnerOptions options;
        options.view = view;
        if (progress) {
          options.progress = [progress](double t, double d) {
            py::gil_scoped_acquire gil;
            progress(t, d);
          };
        }
        {
          py::gil_scoped_release release;
          run->result = scenario::RunScenario(*run->spec, options);
        }
        run->result.spec = run->spec.get();
        return run;
      },
      py::arg("spec"), py::arg("view") = false, py::arg("progress") = nullptr,
      "Runs a scenario: simulator or log, every configuration, evaluation and expectations.");
}

}  // namespace slamrig::python
