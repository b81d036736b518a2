#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "slam/config/yaml_node.h"
#include "slam/eval/json_writer.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"

namespace slamrig::slam {

/// One named SLAM configuration: an algorithm, its options, and how odometry reaches it.
/// Copies share nothing (the options are cloned).
struct EstimatorConfig {
  std::string name = "pf";         ///< e.g. `pf_100`; names the outputs (`pf_100.tum`)
  std::string algorithm = "pf";    ///< a name of Algorithms()
  std::string preset = "default";  ///< one of the algorithm's presets
  ScanSyncOptions odometry;  ///< source, gyro, integration; the robot geometry is the source's
  std::unique_ptr<AlgorithmOptions> options;  ///< the algorithm's own options
  /// The source's gyro noise (EstimatorContext::gyro): not a field, it comes from the robot file.
  std::optional<GyroNoiseModel> gyro;

  EstimatorConfig() = default;
  EstimatorConfig(const EstimatorConfig& other);
  EstimatorConfig& operator=(const EstimatorConfig& other);
  EstimatorConfig(EstimatorConfig&&) = default;
  EstimatorConfig& operator=(EstimatorConfig&&) = default;
};

/// The default configuration of `algorithm` (its first preset), named `name`; a ConfigError
/// listing the algorithms when there is no such algorithm.
EstimatorConfig DefaultEstimatorConfig(const std::string& name, const std::string& algorithm);

/// Reads one configuration from a map:
///
/// ```yaml
/// pf:                         # the configuration's name
///   algorithm: pf             # a name of Algorithms(): pf, dead-reckoning, ...
///   preset: default           # the algorithm's presets (pf: default | reports)
///   odometry: {source: auto, use_gyro: true, integration: exact_arc}
///   particles: 100            # ... every key of the algorithm's field table
/// ```
///
/// Every key is checked (unknown keys are left for the document's CheckAllKeysUsed(), which
/// names them); every broken rule is one ConfigError naming the file, line and key path.
EstimatorConfig ParseEstimatorConfig(const std::string& name, const YamlNode& node);

/// Reads the algorithm's fields of `node` into `config` (keys not in its table are left alone):
/// command-line flags that set fields go through here too.
void ReadEstimatorFields(const YamlNode& node, EstimatorConfig* config);

/// Writes `config` as the map ParseEstimatorConfig reads (every field, resolved).
void WriteEstimatorConfig(const EstimatorConfig& config, YAML::Emitter* out);

/// Writes `config` into the open object of `json` with the same keys.
void WriteEstimatorConfigJson(const EstimatorConfig& config, JsonWriter* json);

/// A new estimator for `config`; its seed is the stream "slam.<name>" of `run_seed`.
std::unique_ptr<Estimator> MakeEstimator(const EstimatorConfig& config, std::uint64_t run_seed,
                                         bool own_odometry = true);

}  // namespace slamrig::slam
