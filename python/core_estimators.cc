// slamrig._core: estimators, their inputs and their runs.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "python/core_internal.h"
#include "python/python_estimator.h"
#include "slam/config/yaml_node.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/pipeline/python_estimator.h"
#include "slam/types/random_stream.h"

namespace slamrig::python {

using slam::Dataset;
using slam::EstimatorConfig;
using slam::EstimatorRun;
using slam::ScanEstimate;
using slam::SyncedScan;

void DefineEstimatorInputs(py::module_& m) {
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
}

void DefineEstimatorRuns(py::module_& m) {
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
}

}  // namespace slamrig::python
