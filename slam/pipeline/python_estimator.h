#pragma once

// The `python` algorithm's options: an estimator written in Python, named by module and class,
// with free options passed to the class. The pipeline itself knows no Python: the bindings
// (python/) install the factory that imports the module and wraps the object in an Estimator,
// the embedded interpreter for the command line and the module for `import slamrig`. Without
// it (a build without SLAMRIG_PYTHON) the algorithm is listed but making one is an error.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "slam/config/fields.h"
#include "slam/pipeline/algorithm.h"

namespace slamrig::slam {

/// One free option of a Python estimator: a YAML scalar, typed as YAML reads it.
using PythonOptionValue = std::variant<bool, std::int64_t, double, std::string>;

struct PythonEstimatorOptions {
  std::string module;      ///< `module:` imported from `path`, then PYTHONPATH and sys.path
  std::string class_name;  ///< `class:` in the module, called with the free options as keywords
  /// `path:` a folder put first on sys.path; relative to the scenario file, which is the default.
  std::string path;
  /// Every other key of the configuration, in file order, passed to the class as keywords.
  std::vector<std::pair<std::string, PythonOptionValue>> options;
  /// An object (class or instance) given from Python instead of module and class; opaque here
  /// (the bindings' py::object), never written to a file.
  std::shared_ptr<void> object;

  std::vector<std::string> Validate() const;
};

/// Makes the Estimator of `options` (set by the bindings; empty without them).
using PythonEstimatorFactory = std::function<std::unique_ptr<Estimator>(
    const PythonEstimatorOptions&, const EstimatorContext&)>;
void SetPythonEstimatorFactory(PythonEstimatorFactory factory);

/// The AlgorithmOptions of the python algorithm: the free options have no fixed table, so it
/// reads every key of the configuration that is not the configuration's own.
class PythonAlgorithmOptions final : public AlgorithmOptions {
 public:
  explicit PythonAlgorithmOptions(PythonEstimatorOptions options = {})
      : options_(std::move(options)) {}
  std::unique_ptr<AlgorithmOptions> Clone() const override {
    return std::make_unique<PythonAlgorithmOptions>(options_);
  }
  void Visit(FieldReader& reader) override;
  void Visit(FieldWriter& writer) override { Write(writer); }
  void Visit(JsonFieldWriter& writer) override { Write(writer); }
  std::vector<std::string> Validate() const override { return options_.Validate(); }
  std::unique_ptr<Estimator> MakeEstimator(const EstimatorContext& context) const override;

  const PythonEstimatorOptions& options() const { return options_; }
  PythonEstimatorOptions& options() { return options_; }

 private:
  template <typename W>
  void Write(W& writer) {
    writer("module", options_.module);
    writer("class", options_.class_name);
    writer("path", options_.path);
    for (auto& entry : options_.options) {
      // Not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda.
      const std::string& key = entry.first;
      std::visit(
          [&](auto v) {
            if constexpr (std::is_same_v<decltype(v), std::int64_t>) {
              double as_double = static_cast<double>(v);  // the writers take int or double
              if (v >= INT32_MIN && v <= INT32_MAX) {
                int as_int = static_cast<int>(v);
                writer(key.c_str(), as_int);
              } else {
                writer(key.c_str(), as_double);
              }
            } else {
              writer(key.c_str(), v);
            }
          },
          entry.second);
    }
  }

  PythonEstimatorOptions options_;
};

}  // namespace slamrig::slam
