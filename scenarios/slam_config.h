#pragma once

#include <string>
#include <vector>

#include "slam/config/yaml_node.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/particle_filter_options.h"

namespace slamrig::scenario {

/// The SLAM algorithms a scenario can run.
enum class SlamAlgorithm {
  kDeadReckoning,   ///< odometry alone (the map is built along it)
  kParticleFilter,  ///< particle-filter SLAM (slam/pf)
};

/// One named SLAM configuration of a scenario, e.g. `pf_100` or `dead_reckoning`.
struct SlamConfig {
  std::string name;
  SlamAlgorithm algorithm = SlamAlgorithm::kParticleFilter;
  slam::ParticleFilterOptions pf;  ///< particle filter settings (and its map)
  slam::OccupancyGridOptions map;  ///< dead reckoning's map
  slam::ScanSyncOptions sync;      ///< odometry: source, robot geometry, gyro
};

/// Reads one `slam:` entry:
///
/// ```yaml
/// pf:                                 # the configuration's name
///   algorithm: pf                     # pf | dead-reckoning
///   preset: default                   # default | reports (the ECE276A reports' method)
///   particles: 100
///   motion_noise: rot_trans_rot       # gaussian | rot_trans_rot
///   sigma_xy_m: 0.01                  # gaussian noise per scan step
///   sigma_yaw_rad: 0.005
///   rot_trans_rot: {alpha1: 0.02, alpha2: 0.002, alpha3: 0.01, alpha4: 0.0005,
///                   min_trans_sigma_m: 0.005, min_rot_sigma_rad: 0.003}
///   observation: correlation          # correlation | likelihood_field
///   points: {min_range_m: 0.1, max_range_m: 30, beam_stride: 1, voxel_size_m: 0.05}
///   correlation: {xy_half_width_cells: 4, yaw_half_steps: 2, yaw_step_rad: 0.01,
///                 value: occupied | log_odds, occupied_threshold: 0}
///   likelihood_field: {sigma_m: 0.05, z_hit: 0.9, z_rand: 0.1, cutoff_sigmas: 3}
///   observation_scale: 1.0
///   move_to_best_shift: true
///   refine: true                      # Gauss-Newton refinement on the likelihood field
///   refiner: {max_iterations: 6, max_step_m: 0.05, max_step_rad: 0.02, converged_step_m: 1e-4}
///   min_update_distance_m: 0.25       # filter only after this much motion (odometry between)
///   min_update_angle_rad: 0.1
///   resampling: systematic            # systematic | stratified
///   resample_neff_ratio: 0.5
///   threads: 1
///   map: {resolution_m: 0.05, hit_log_odds: 1.386, miss_log_odds: -0.405, min_log_odds: -5,
///         max_log_odds: 5, max_range_m: 30, no_return_clear_range_m: 10,
///         update_once_per_scan: true}
///   odometry: {source: auto, use_gyro: true, integration: exact_arc}   # auto | wheel_ticks |
///   poses
/// ```
/// Every broken rule is a ConfigError naming the file, line and key.
SlamConfig ParseSlamConfig(const std::string& name, const YamlNode& node);

/// Reads map options from `node` into `*options` (absent keys keep their values).
void ParseGridOptions(const YamlNode& node, slam::OccupancyGridOptions* options);

/// A YAML rendering of `config` (every field, resolved), for the report's resolved config.
std::string SlamConfigToYaml(const SlamConfig& config);

}  // namespace slamrig::scenario
