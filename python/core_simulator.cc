// slamrig._core: the simulator.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "python/arrays.h"
#include "python/core_internal.h"
#include "python/python_estimator.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world_yaml.h"
#include "slam/types/error.h"

namespace slamrig::python {

void DefineSimulator(py::module_& m) {
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
}

}  // namespace slamrig::python
