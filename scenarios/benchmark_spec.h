#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace slamrig::scenario {

/// One estimator of a suite: a scenario `slam:` entry.
struct BenchmarkEstimator {
  std::string name;  ///< its configuration name, e.g. pf
  std::string yaml;  ///< its entry as flow YAML, e.g. {algorithm: pf, particles: 100}
};

/// One dataset of a suite: a real log (perturbed or not) or a family of generated worlds, each
/// run at every seed.
struct BenchmarkDataset {
  std::string name;   ///< the family's name in results.csv and the leaderboard
  std::string where;  ///< its place in the suite file, "suite.yaml:12:5"
  /// A log (absolute path), or "" for generated worlds.
  std::string log;
  std::string perturb_yaml;   ///< flow YAML of `perturb:` ("" for none)
  std::size_t max_scans = 0;  ///< a log: use the records up to this many scans (0: all)
  /// Generated worlds: flow YAML of `generate:` without its seed (the run's seed is the world's).
  std::string generate_yaml;
  /// A world file (absolute path; "" for none), the same world at every seed, and flow YAML of
  /// its `world_overrides:` ("" for none).
  std::string world;
  std::string world_overrides_yaml;
  std::string robot;                 ///< a robot file (absolute) or preset name; "" default
  std::string robot_overrides_yaml;  ///< flow YAML ("" for none)
  double duration_s = 0.0;           ///< 0: the scenario's default (a log: whole)
  std::vector<std::uint64_t> seeds;  ///< each a run (generated: the world's seed too)
};

/// A benchmark suite: estimators x datasets.
///
/// ```yaml
/// timeout_s: 900                          # a run still going then is a failure (default 1800)
/// fail_above_m: 1.0                       # a run whose ATE RMSE is above it failed (default 1)
/// estimators:                             # scenario `slam:` entries
///   pf: {algorithm: pf, particles: 100}
///   graph: {algorithm: graph}
/// datasets:
///   - name: intel                         # a real log, beside the suite or in SLAMRIG_DATA_DIR
///     log: carmen_corrected/intel-corrected.log.gz
///   - name: intel_2x_odometry_noise       # the same log, perturbed as it is read
///     log: carmen_corrected/intel-corrected.log.gz
///     perturb: {odometry.noise_per_m: 0.15, odometry.noise_per_rad: 0.4}
///     seeds: [1, 2, 3]                    # each seed a different perturbation
///   - name: office                        # generated worlds: one per seed
///     generate: {kind: office, width_m: 40, height_m: 30}
///     seeds: {from: 1, to: 20}
///     robot: ../robots/sick_lms200_1deg.yaml
///     duration_s: 300
/// ```
struct BenchmarkSuite {
  std::string path;
  double timeout_s = 1800.0;
  double fail_above_m = 1.0;  ///< a run whose ATE RMSE is above this failed
  std::vector<BenchmarkEstimator> estimators;
  std::vector<BenchmarkDataset> datasets;
};

/// One run of a suite: an estimator on one dataset at one seed.
struct BenchmarkRun {
  std::string id;  ///< "dataset seed=S estimator"
  std::size_t dataset = 0, estimator = 0;
  std::uint64_t seed = 0;
};

/// The configuration every run carries beside its estimator, for the failure criterion.
inline constexpr char kBaselineName[] = "dead_reckoning";

/// Reads a suite strictly: an unknown key, a bad world kind or parameter, a bad perturbation, an
/// estimator the scenario loader refuses, a log that is not there or a bad seed range is a
/// ConfigError naming file:line:col and the key (`datasets[2].generate.kind: unknown kind
/// 'ofice'; ...`). Each dataset's scenario is resolved once (its first seed) with every
/// estimator, so that nothing starts before all of it is known to run.
BenchmarkSuite LoadBenchmarkSuite(const std::string& path);

/// Every dataset x seed x estimator, datasets and seeds in file order, estimators fastest.
std::vector<BenchmarkRun> ExpandBenchmark(const BenchmarkSuite& suite);

/// The scenario file of `run` (what `slamrig run` is given): the dataset's source, the
/// estimator and the dead-reckoning baseline, the run's seed, no expectations.
std::string BenchmarkScenarioYaml(const BenchmarkSuite& suite, const BenchmarkRun& run);

}  // namespace slamrig::scenario
