#include "slam/pipeline/estimator_config.h"

#include <algorithm>

#include "slam/types/error.h"
#include "slam/types/random_stream.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

const Algorithm& Require(const std::string& algorithm, const YamlNode* where) {
  if (const Algorithm* a = FindAlgorithm(algorithm)) return *a;
  const std::string message =
      "unknown algorithm '" + algorithm + "'; expected one of " + AlgorithmNames();
  if (where != nullptr) where->Fail(message);
  throw ConfigError(message);
}

std::unique_ptr<AlgorithmOptions> PresetOptions(const Algorithm& algorithm,
                                                const std::string& preset, const YamlNode* where) {
  if (std::find(algorithm.presets.begin(), algorithm.presets.end(), preset) ==
      algorithm.presets.end()) {
    std::string names;
    for (const auto& p : algorithm.presets) names += (names.empty() ? "" : ", ") + p;
    const std::string message =
        "unknown preset '" + preset + "' of " + algorithm.name + "; expected one of " + names;
    if (where != nullptr) where->Fail(message);
    throw ConfigError(message);
  }
  return algorithm.make_options(preset);
}

}  // namespace

EstimatorConfig::EstimatorConfig(const EstimatorConfig& other)
    : name(other.name),
      algorithm(other.algorithm),
      preset(other.preset),
      odometry(other.odometry),
      options(other.options ? other.options->Clone() : nullptr),
      gyro(other.gyro) {}

EstimatorConfig& EstimatorConfig::operator=(const EstimatorConfig& other) {
  if (this != &other) *this = EstimatorConfig(other);
  return *this;
}

EstimatorConfig DefaultEstimatorConfig(const std::string& name, const std::string& algorithm) {
  const Algorithm& a = Require(algorithm, nullptr);
  EstimatorConfig config;
  config.name = name;
  config.algorithm = a.name;
  config.preset = a.presets.front();
  config.options = a.make_options(config.preset);
  return config;
}

EstimatorConfig ParseEstimatorConfig(const std::string& name, const YamlNode& node) {
  if (!node.IsMap()) node.Fail("a SLAM configuration is a map (algorithm: ..., ...)");
  if (name.empty() || name.find_first_of(" ,./\"=") != std::string::npos) {
    node.Fail("configuration name '" + name +
              "' must be non-empty, without spaces, commas, dots, slashes or '='");
  }
  EstimatorConfig config;
  config.name = name;
  node.Read("algorithm", &config.algorithm);
  const auto algorithm_node = node.Optional("algorithm");
  const Algorithm& algorithm = Require(config.algorithm, algorithm_node ? &*algorithm_node : &node);
  config.preset = algorithm.presets.front();
  node.Read("preset", &config.preset);
  const auto preset_node = node.Optional("preset");
  config.options = PresetOptions(algorithm, config.preset, preset_node ? &*preset_node : &node);
  if (const auto odometry = node.Optional("odometry")) {
    if (!odometry->IsMap()) odometry->Fail("expected a map");
    FieldReader reader(*odometry);
    VisitFields(reader, config.odometry);
  }
  ReadEstimatorFields(node, &config);
  return config;
}

void ReadEstimatorFields(const YamlNode& node, EstimatorConfig* config) {
  FieldReader reader(node);
  config->options->Visit(reader);
  node.ThrowIfInvalid(PrefixErrors(node.path(), config->options->Validate()));
}

void WriteEstimatorConfig(const EstimatorConfig& config, YAML::Emitter* out) {
  EstimatorConfig copy = config;  // the visitors take mutable references
  *out << YAML::BeginMap << YAML::Key << "algorithm" << YAML::Value << copy.algorithm << YAML::Key
       << "preset" << YAML::Value << copy.preset;
  FieldWriter writer(out);
  writer.Struct("odometry", copy.odometry);
  copy.options->Visit(writer);
  *out << YAML::EndMap;
}

void WriteEstimatorConfigJson(const EstimatorConfig& config, JsonWriter* json) {
  EstimatorConfig copy = config;
  json->String("algorithm", copy.algorithm).String("preset", copy.preset);
  JsonFieldWriter writer(json);
  writer.Struct("odometry", copy.odometry);
  copy.options->Visit(writer);
}

std::unique_ptr<Estimator> MakeEstimator(const EstimatorConfig& config, std::uint64_t run_seed,
                                         bool own_odometry) {
  const std::vector<std::string> errors = config.options->Validate();
  if (!errors.empty()) throw ConfigError(config.name + ": " + errors.front());
  EstimatorContext context;
  context.seed = RandomStream(run_seed, "slam." + config.name).NextU64();
  context.robot = config.odometry.robot;
  context.use_gyro = config.odometry.use_gyro;
  context.gyro = config.gyro;
  context.own_odometry = own_odometry;
  return config.options->MakeEstimator(context);
}

}  // namespace slamrig::slam
