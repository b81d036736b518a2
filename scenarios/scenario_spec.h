#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sim/simulator.h"
#include "slam/io/log_perturbation.h"
#include "slam/io/log_reader.h"
#include "slam/pipeline/estimator_config.h"
#include "slam/texture/texture_map.h"

namespace slamrig::scenario {

/// A threshold a metric of one SLAM configuration must meet, e.g. `pf: {ate_rmse_m_max: 0.1}`.
struct Expectation {
  std::string config;  ///< SLAM configuration name
  std::string metric;  ///< metric name in metrics.json, e.g. ate_rmse_m
  bool is_max = true;  ///< metric <= threshold (from `<metric>_max`), else >= (`<metric>_min`)
  double threshold = 0.0;
};

/// The robot is picked up and put down elsewhere at `at_s` (odometry does not see it).
struct KidnapFault {
  double at_s = 0.0;
  Pose2 to;  ///< new map_from_base
};

/// The lidar delivers nothing in [from_s, to_s).
struct BlackoutFault {
  double from_s = 0.0;
  double to_s = 0.0;
};

/// A simulated source: world, robot and seed, and the faults injected while it runs.
struct SimulatedSource {
  sim::SimulatorOptions options;  ///< world (slip patches and crowd applied), robot, seed
  std::vector<KidnapFault> kidnaps;
  std::vector<BlackoutFault> blackouts;
};

/// A recorded source: a log file, scored against its own reference (a corrected log's poses,
/// TRUEPOS lines).
struct LogSource {
  std::string path;  ///< as resolved (ResolveLogPath)
  slam::LogReadOptions read;
  slam::LogPerturbation perturb;  ///< applied to the records as read (none by default)
  slam::DiffDriveParams robot;    ///< wheel geometry for logs with encoder ticks (ECE276A default)
  std::size_t max_scans = 0;      ///< `max_scans:` use the records up to this many scans (0: all)
  /// `truth_map:` a map_server map (YAML) of the true world, in the reference's frame: the map
  /// every configuration's map is scored against, in place of the log's scans at its reference
  /// poses. Needs a log with a reference.
  std::string truth_map;
};

/// The texture map options a scenario uses unless its `texture:` block says otherwise: every
/// fourth pixel along rows and columns (a 640 x 480 frame keeps ~50 k floor pixels, ~0.2 MB).
inline slam::TextureMapOptions DefaultScenarioTexture() {
  slam::TextureMapOptions o;
  o.pixel_stride = 4;
  return o;
}

/// A scenario: where the records come from (a simulated world or a log), which SLAM
/// configurations run on them, and what they must achieve. Read from scenarios/*.yaml:
///
/// ```yaml
/// name: office_loop
/// description: three laps of the office corridor loop at 0.5 m/s
/// world: ../worlds/office.yaml       # a file (relative to this one), a preset name or a map
/// robot: ../robots/ece276a.yaml      # likewise; optional: sim::kDefaultRobot
/// seed: 1
/// duration_s: 400                    # stop here even if the drive is not finished
/// world_overrides: {drive.laps: 3}   # key path in the world file -> value
/// robot_overrides: {lidar.range_noise_stddev_m: 0.03}
/// faults:
///   slip_patches: [{name: oil, shape: {type: box, center_m: [5, 1.2], size_m: [2, 2]}, mu: 0.05}]
///   crowd: {count: 4, speed_m_s: 0.7, radius_m: 0.25, lateral_offset_m: 0.8}
///   kidnap: [{at_s: 60, to: {x_m: 3, y_m: 1.25, yaw_rad: 0}}]
///   lidar_blackout: [{from_s: 30, to_s: 40}]
/// slam:                              # one or more configurations, compared side by side
///   dead_reckoning: {algorithm: dead-reckoning}
///   pf: {algorithm: pf, particles: 100}
/// expect:
///   pf: {ate_rmse_m_max: 0.10, map_f1_min: 0.8, realtime_factor_min: 5}
/// ```
///
/// or, instead of world/robot/faults, a log: `source: {log:
/// carmen_corrected/intel-corrected.log.gz}` (relative to this file or to SLAMRIG_DATA_DIR;
/// `lenient: true` counts malformed lines; `strict: true` refuses a log cut short (else read up
/// to the cut, with a note); a ROS 2 bag's topics other than the defaults as
/// `topics: {scan: /front/scan, odom: /wheel_odom}`, keys as in slam::BagTopicNames).
struct ScenarioSpec {
  std::string path;
  std::string name;
  std::string description;
  std::uint64_t seed = 1;     ///< the simulator's and every estimator's streams derive from it
  double duration_s = 600.0;  ///< simulated: stop here; log: use the records up to here
  bool has_duration = false;  ///< duration_s was given (a log runs whole otherwise)
  std::optional<SimulatedSource> simulated;  ///< exactly one of simulated and log
  std::optional<LogSource> log;
  std::vector<slam::EstimatorConfig> configs;
  /// The texture map's raster (`texture:`; extents come from the world's floor) for a robot with a
  /// camera.
  slam::TextureMapOptions texture = DefaultScenarioTexture();
  std::vector<Expectation> expectations;
  /// `record: true`: write run.mcap for Foxglove in the report folder (as `--record` does).
  bool record = false;
  /// The whole resolved scenario, in the input schema (world and robot inline, every field):
  /// `slamrig run config.yaml` repeats the run bit for bit.
  std::string resolved_yaml;
};

/// Metric names any configuration may have (metrics.json per configuration); a run gives each
/// configuration the ones that apply to it (a reference, a camera, kidnappings, a covariance).
const std::vector<std::string>& KnownMetrics();

/// The scores of accepted loop closures against the reference (algorithms that close loops).
const std::vector<std::string>& LoopMetrics();

/// Metrics of the `truth` pseudo-configuration of a run with a camera: the texture map from the
/// true poses (`expect: {truth: {texture_psnr_db_min: 20}}`).
const std::vector<std::string>& TruthMetrics();

/// The scores of a landmark map against the world's pillars (simulated runs of algorithms that
/// map landmarks).
const std::vector<std::string>& LandmarkMetrics();

/// The lost intervals of an estimator that judges itself (it declares `diverged`): their count
/// and total seconds, from its per-scan lost flags (slam/pipeline/health.h).
const std::vector<std::string>& HealthMetrics();

/// The metrics of `config`, which `expect:` accepts: KnownMetrics(), its algorithm's statistics
/// (as its estimator declares them), HealthMetrics() for one that judges itself and, for an
/// algorithm that closes loops or maps landmarks, LoopMetrics() or LandmarkMetrics().
std::vector<std::string> MetricsOf(const slam::EstimatorConfig& config);

/// A scenario of one log and `configs`, as a command builds it from its flags (`slamrig slam`):
/// named after the log, `origin` saying where it came from (in messages and config.yaml, which
/// `slamrig run` repeats bit for bit).
ScenarioSpec LogScenario(const LogSource& log, std::vector<slam::EstimatorConfig> configs,
                         std::uint64_t seed, const std::string& origin);

/// Reads a scenario file strictly. `overrides` are `key=value` texts: keys starting with
/// `world.` or `robot.` change the world or robot file, others the scenario file itself (e.g.
/// `slam.pf.particles=30`); errors about an overridden value name the `--set` argument. `seed`,
/// when given, replaces the file's seed. Every error is a ConfigError naming the file, line and
/// key.
ScenarioSpec LoadScenario(const std::string& path, const std::vector<std::string>& overrides = {},
                          std::optional<std::uint64_t> seed = std::nullopt);

/// The scenario file `name_or_path`: a path, or a shipped scenario's name ("office_loop") looked
/// up in scenarios/ of the current folder, of the source tree and of the installed share folder.
std::string FindScenarioFile(const std::string& name_or_path);

}  // namespace slamrig::scenario
