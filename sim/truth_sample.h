#pragma once

#include <Eigen/Core>
#include <vector>

#include "sim/robot.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"
#include "slam/types/time.h"

namespace slamrig::sim {

/// The simulator's ground truth at one instant. It travels on its own channel beside the sensor
/// records; only evaluation may read it.
struct TruthSample {
  Time time;                                               ///< the record's time
  Pose2 map_from_base;                                     ///< interpolated between physics steps
  Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();  ///< base_link velocity, map frame
  double yaw_rate_rad_s = 0.0;                             ///< CCW positive
  std::vector<WheelState> wheels;  ///< wheel and contact state of the physics step holding `time`
  /// For a lidar scan: the noise-free range of each beam (range_max_m where nothing was hit), so
  /// evaluation can build the map the sensor would see of the world itself. Empty otherwise.
  std::vector<float> true_ranges_m;

  /// The pose as the ground-truth record the evaluation reads.
  GroundTruthPose ToGroundTruthPose() const { return {time, map_from_base}; }
};

}  // namespace slamrig::sim
