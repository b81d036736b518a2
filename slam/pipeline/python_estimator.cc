#include "slam/pipeline/python_estimator.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <mutex>

#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

std::mutex& FactoryMutex() {
  static std::mutex mutex;
  return mutex;
}

PythonEstimatorFactory& Factory() {
  static PythonEstimatorFactory factory;
  return factory;
}

// The configuration's own keys (estimator_config.cc reads them); the rest go to the class.
constexpr std::array<const char*, 6> kOwnKeys = {"algorithm", "preset", "odometry",
                                                 "module",    "class",  "path"};

// A YAML scalar as YAML 1.2's core schema types it: integer, float, bool, else text.
PythonOptionValue TypedScalar(const YamlNode& node) {
  const std::string text = node.As<std::string>();
  const auto is = [&](const char* pattern) { return text == pattern; };
  if (is("true") || is("True") || is("false") || is("False")) return node.As<bool>();
  try {
    return node.As<std::int64_t>();
  } catch (const ConfigError&) {
  }
  try {
    return node.As<double>();
  } catch (const ConfigError&) {
  }
  return text;
}

}  // namespace

std::vector<std::string> PythonEstimatorOptions::Validate() const {
  Rules rules;
  if (object) return rules.errors();
  rules.Required(!module.empty(), "module", "the Python module to import")
      .Required(!class_name.empty(), "class", "the estimator class of the module");
  return rules.errors();
}

void SetPythonEstimatorFactory(PythonEstimatorFactory factory) {
  std::lock_guard lock(FactoryMutex());
  Factory() = std::move(factory);
}

void PythonAlgorithmOptions::Visit(FieldReader& reader) {
  namespace fs = std::filesystem;
  const YamlNode& node = reader.node();
  node.Read("module", &options_.module);
  node.Read("class", &options_.class_name);
  // Module search starts in the scenario's folder (or `path:` relative to it), so a scenario
  // and its estimator can live side by side; written resolved, so config.yaml runs anywhere.
  std::error_code error;
  const fs::path file(node.file());
  const bool from_file = fs::is_regular_file(file, error);
  const fs::path folder = from_file ? fs::absolute(file, error).parent_path() : fs::current_path();
  if (const auto path = node.Optional("path")) {
    options_.path = (folder / path->As<std::string>()).lexically_normal().string();
  } else if (options_.path.empty() && from_file) {
    options_.path = folder.lexically_normal().string();
  }
  for (const std::string& key : node.Keys()) {
    if (std::find(kOwnKeys.begin(), kOwnKeys.end(), key) != kOwnKeys.end()) continue;
    const YamlNode child = node.Required(key);
    if (!child.IsScalar()) {
      child.Fail("a python estimator's option is a number, a bool or a text (passed as a keyword)");
    }
    const PythonOptionValue value = TypedScalar(child);
    auto it = std::find_if(options_.options.begin(), options_.options.end(),
                           [&](const auto& option) { return option.first == key; });
    if (it != options_.options.end()) {
      it->second = value;
    } else {
      options_.options.emplace_back(key, value);
    }
  }
}

std::unique_ptr<Estimator> PythonAlgorithmOptions::MakeEstimator(
    const EstimatorContext& context) const {
  PythonEstimatorFactory factory;
  {
    std::lock_guard lock(FactoryMutex());
    factory = Factory();
  }
  if (!factory) {
    throw ConfigError(
        "algorithm python: this slamrig was built without Python (install pybind11-dev and "
        "python3-dev, configure with -DSLAMRIG_PYTHON=ON)");
  }
  return factory(options_, context);
}

}  // namespace slamrig::slam
