// slamrig._core: datasets read from logs.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "python/arrays.h"
#include "python/core_internal.h"
#include "python/python_estimator.h"
#include "slam/io/log_reader.h"

namespace slamrig::python {

using slam::Dataset;

void DefineLogs(py::module_& m) {
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
}

}  // namespace slamrig::python
