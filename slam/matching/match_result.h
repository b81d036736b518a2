#pragma once

#include <Eigen/Core>

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// What every scan matcher (IcpMatcher, CorrelativeMatcher) returns on success; a failed match is
/// std::nullopt instead. The covariance is over (x, y, yaw) of `pose` in the reference frame, in
/// m^2, m rad and rad^2; each matcher documents how it computes it.
struct MatchResult {
  Pose2 pose;  ///< reference_from_source: where the matched scan's base frame is in the reference
  /// Quality in [0, 1], higher is better: ICP's share of source points kept as inliers, the
  /// correlative matcher's mean raster value over the points.
  double score = 0.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  int iterations = 0;       ///< ICP iterations, or branch-and-bound nodes scored
  int correspondences = 0;  ///< points that took part in the final estimate
  bool converged = false;   ///< ICP: the step fell below the tolerance; correlative: always true
};

}  // namespace slamrig::slam
