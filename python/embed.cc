#include "python/embed.h"

#include <pybind11/embed.h>

#include <mutex>

#include "python/core.h"
#include "python/python_estimator.h"
#include "slam/pipeline/python_estimator.h"

namespace py = pybind11;

namespace {

// The builtin module `slamrig._core` of the embedded interpreter: found before any _core.so on
// sys.path, so `import slamrig` in an estimator gets this binary's types.
PyObject* InitEmbeddedCore() {
  static py::module_::module_def definition;
  try {
    auto m = py::module_::create_extension_module("slamrig._core", nullptr, &definition);
    slamrig::python::DefineCore(m, /*embedded=*/true);
    return m.release().ptr();
  } catch (py::error_already_set& e) {
    e.restore();
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_ImportError, e.what());
  }
  return nullptr;
}

void StartInterpreter() {
  static std::once_flag once;
  std::call_once(once, [] {
    PyImport_AppendInittab("slamrig._core", &InitEmbeddedCore);
    // No signal handlers: Ctrl-C stays the command line's.
    py::initialize_interpreter(/*init_signal_handlers=*/false);
    {
      // The package of the build tree, last: an installed or PYTHONPATH one wins.
      py::module_ sys = py::module_::import("sys");
      py::list path = sys.attr("path");
      path.append(SLAMRIG_PYTHON_PACKAGE_DIR);
      // Importing the package defines the types the estimator adapter converts to. Without the
      // package (an installed binary alone) the core module is made by hand: the types are
      // what the adapter needs, and `import slamrig` in an estimator then fails clearly.
      try {
        py::module_::import("slamrig");
      } catch (py::error_already_set&) {
        PyErr_Clear();
        PyObject* core = InitEmbeddedCore();
        if (core == nullptr) throw py::error_already_set();
        sys.attr("modules")["slamrig._core"] = py::reinterpret_steal<py::object>(core);
      }
    }
    // Release the GIL: every call into Python takes it (estimators may run on other threads).
    PyEval_SaveThread();
  });
}

}  // namespace

namespace slamrig::python {

void EnableEmbeddedPython() {
  slam::SetPythonEstimatorFactory(
      [](const slam::PythonEstimatorOptions& options, const slam::EstimatorContext& context) {
        StartInterpreter();
        return MakePythonEstimator(options, context, /*embedded=*/true);
      });
}

}  // namespace slamrig::python
