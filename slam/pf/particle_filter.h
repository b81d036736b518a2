#pragma once

#include <memory>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/likelihood_field.h"
#include "slam/matching/map_correlator.h"
#include "slam/matching/scan_refiner.h"
#include "slam/pf/particle_filter_options.h"
#include "slam/pf/thread_pool.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// One pose hypothesis and its normalised weight.
struct Particle {
  Pose2 pose;
  double weight = 0.0;
};

/// What one AddScan did.
struct ParticleFilterStep {
  Pose2 best_pose;    ///< pose of the highest-weight particle (the map was updated there)
  Pose2 mean_pose;    ///< weighted mean (circular mean for yaw)
  double neff = 0.0;  ///< effective sample size after the update, before resampling
  bool resampled = false;
  bool updated = false;     ///< false: the robot moved too little, poses follow the odometry
  float best_score = 0.0f;  ///< observation score of the best particle
  int points_used = 0;      ///< scan points used for weighting
};

/// Particle-filter SLAM on one shared log-odds map, as in the UCSD ECE276A reports (Wang,
/// "Simultaneous Localization and Mapping with Texture", Sec. II-III; Zafari, "Particle Filter
/// SLAM", algorithm steps 1-7): predict every particle with the odometry increment plus noise,
/// score its scan against the map over a shift grid (map correlation or likelihood field), update
/// the weights by softmax, update the map from the best particle, and resample when Neff drops.
/// Deterministic for a seed, whatever `num_threads` is.
class ParticleFilter {
 public:
  explicit ParticleFilter(const ParticleFilterOptions& options);

  /// Processes one scan. `odometry_increment` is the robot-frame motion since the previous scan
  /// (ignored for the first scan, which only starts the map at the identity pose).
  ParticleFilterStep AddScan(const LaserScan& scan, const Pose2& odometry_increment);

  const std::vector<Particle>& particles() const { return particles_; }
  const OccupancyGrid& map() const { return map_; }
  const ParticleFilterOptions& options() const { return options_; }
  /// Number of resampling events so far.
  int resample_count() const { return resample_count_; }

 private:
  void Predict(const Pose2& odometry_increment);
  std::vector<double> Score(const std::vector<Eigen::Vector2d>& points, float* best_score);

  ParticleFilterOptions options_;
  OccupancyGrid map_;
  MapCorrelator correlator_;
  LikelihoodField likelihood_field_;
  OccupiedMask occupied_mask_;  // the map's walls for the occupied-indicator correlation
  ScanRefiner refiner_;
  RandomEngine rng_;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<Particle> particles_;
  std::vector<double> log_weights_;
  bool started_ = false;
  Pose2 pending_motion_;  // odometry since the last update
  ParticleFilterStep last_step_;
  int resample_count_ = 0;
};

/// Weighted mean of particle poses: arithmetic in x, y; circular in yaw.
Pose2 WeightedMeanPose(const std::vector<Particle>& particles);

}  // namespace slamrig::slam
