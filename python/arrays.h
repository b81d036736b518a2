#pragma once

// NumPy arrays over C++ buffers. Every view names a Python object as its base (the wrapper of
// the C++ object that owns the buffer), so the buffer lives as long as the array does; views are
// read-only where the C++ side may still change or reallocate the buffer.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <vector>

#include "slam/types/records.h"
#include "slam/types/trajectory.h"

namespace slamrig::python {

namespace py = pybind11;

/// A view of `data` with `shape` and byte `strides`, kept alive by `base`.
template <typename T>
py::array View(const T* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
               py::handle base, bool writeable = false) {
  py::array array(py::dtype::of<T>(), std::move(shape), std::move(strides), data, base);
  if (!writeable) {
    py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  }
  return array;
}

/// A contiguous 1-D view.
template <typename T>
py::array View1(const T* data, std::size_t n, py::handle base, bool writeable = false) {
  return View(data, {static_cast<py::ssize_t>(n)}, {static_cast<py::ssize_t>(sizeof(T))}, base,
              writeable);
}

// A StampedPose is an int64 stamp followed by three doubles (x, y, theta), 32 bytes with no
// padding, so a trajectory's poses are an (N, 3) float64 view with a 32-byte row stride.
static_assert(sizeof(Time) == 8 && sizeof(Pose2) == 24 && sizeof(StampedPose) == 32);
static_assert(sizeof(GroundTruthPose) == 32);

/// (N, 3) x, y, yaw of `poses` (StampedPose or GroundTruthPose), no copy.
template <typename P>
py::array PoseView(const std::vector<P>& poses, py::handle base) {
  static_assert(sizeof(P) == 32);
  const auto* first = reinterpret_cast<const double*>(
      reinterpret_cast<const std::byte*>(poses.data()) + sizeof(Time));
  return View(first, {static_cast<py::ssize_t>(poses.size()), 3}, {32, 8}, base);
}

/// (N,) int64 nanosecond stamps of `poses`, no copy.
template <typename P>
py::array StampView(const std::vector<P>& poses, py::handle base) {
  const auto* first = reinterpret_cast<const std::int64_t*>(poses.data());
  return View(first, {static_cast<py::ssize_t>(poses.size())}, {32}, base);
}

}  // namespace slamrig::python
