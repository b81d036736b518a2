#pragma once

namespace slamrig::python {

/// Lets the command line run `algorithm: python`: installs the Python estimator factory, which
/// starts an interpreter in this process the first time a Python estimator is made (so runs
/// without one never load Python). The interpreter's `slamrig._core` is this binary's own
/// definition, so a Python estimator sees the same types as the C++ code that feeds it.
void EnableEmbeddedPython();

}  // namespace slamrig::python
