// The extension module `slamrig._core` (`import slamrig`).

#include <pybind11/pybind11.h>

#include "python/core.h"

PYBIND11_MODULE(_core, m) { slamrig::python::DefineCore(m, /*embedded=*/false); }
