// slamrig._core: scenarios and their results.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "python/core_internal.h"
#include "python/python_estimator.h"
#include "slam/types/error.h"

namespace slamrig::python {

using slam::EstimatorConfig;

void DefineScenarioSpec(py::module_& m) {
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
}

void DefineScenarioRuns(py::module_& m) {
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
