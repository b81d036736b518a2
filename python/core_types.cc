// slamrig._core: poses, records, trajectories and grids.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <string>
#include <vector>

#include "python/arrays.h"
#include "python/core_internal.h"
#include "python/python_estimator.h"
#include "slam/types/error.h"

namespace slamrig::python {

void DefineRecords(py::module_& m) {
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
}

void DefineTrajectoryAndGrid(py::module_& m) {
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
                            "A log-odds grid; `log_odds` is an (H, W) copy, row 0 at the lowest y.")
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
          [](const OccupancyGrid& g) {
            // The grid is tiles, not one array: a dense copy, read-only like the other records.
            py::array_t<float> a({g.height(), g.width()});
            g.CopyLogOdds({0, 0}, {g.width(), g.height()}, a.mutable_data(), g.width());
            a.attr("flags").attr("writeable") = false;
            return a;
          },
          "(H, W) float32, read-only copy (the grid's cells at the time of the call)")
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
      .def("insert_scan", &OccupancyGrid::InsertScan, py::arg("scan"), py::arg("world_from_base"),
           py::arg("max_range_m") = py::none());
}

}  // namespace slamrig::python
