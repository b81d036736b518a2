#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scenarios/slam_config.h"
#include "sim/simulator.h"

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

/// A scenario: a world, a robot, how it drives, what goes wrong, which SLAM configurations run,
/// and what they must achieve. Read from scenarios/*.yaml:
///
/// ```yaml
/// name: office_loop
/// description: three laps of the office corridor loop at 0.5 m/s
/// world: ../worlds/office.yaml       # relative to this file
/// robot: ../robots/ece276a.yaml
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
struct ScenarioSpec {
  std::string path;
  std::string name;
  std::string description;
  sim::SimulatorOptions sim;  ///< world (with faults applied), robot and seed
  double duration_s = 600.0;
  std::vector<KidnapFault> kidnaps;
  std::vector<BlackoutFault> blackouts;
  std::vector<SlamConfig> slam;
  std::vector<Expectation> expectations;
  std::string resolved_yaml;  ///< the whole resolved configuration, written next to results
};

/// Metric names a scenario may set expectations on (metrics.json per configuration).
const std::vector<std::string>& KnownMetrics();

/// Reads a scenario file strictly. `overrides` are `key=value` texts: keys starting with
/// `world.` or `robot.` change the world or robot file, others the scenario file itself (e.g.
/// `slam.pf.particles=30`). `seed`, when given, replaces the file's seed. Every error is a
/// ConfigError naming the file, line and key.
ScenarioSpec LoadScenario(const std::string& path, const std::vector<std::string>& overrides = {},
                          std::optional<std::uint64_t> seed = std::nullopt);

}  // namespace slamrig::scenario
