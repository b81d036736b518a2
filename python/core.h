#pragma once

#include <pybind11/pybind11.h>

namespace slamrig::python {

/// Defines the classes and functions of `slamrig._core` in `m`: the extension module and the
/// interpreter embedded in the command line share this one definition. `embedded`: the command
/// line already installed its own Python estimator factory.
void DefineCore(pybind11::module_& m, bool embedded);

}  // namespace slamrig::python
