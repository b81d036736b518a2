#pragma once

#include <string>
#include <vector>

#include "slam/eval/error_stats.h"
#include "slam/eval/pose_association.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// Absolute trajectory error after SE(2) alignment (Sturm et al., "A Benchmark for the
/// Evaluation of RGB-D SLAM Systems", IROS 2012, Sec. V-A, in the plane).
struct AteResult {
  ErrorStats translation_m;
  ErrorStats rotation_rad;
  Pose2 reference_from_estimate;  ///< the alignment applied to the estimate
};

/// ATE of `estimate` against `reference`, poses paired by AssociatePoses.
AteResult ComputeAte(const Trajectory& estimate, const Trajectory& reference,
                     const AssociationOptions& options = {});

/// Relative pose error over pose pairs (Sturm et al. 2012, Sec. V-B): for each i the pair (i, j)
/// with j = i + 1 (`distance_m` = 0) or the first pose whose reference path length from i
/// reaches `distance_m`; the error is (ref_i^-1 ref_j)^-1 (est_i^-1 est_j).
struct RpeResult {
  double distance_m = 0.0;  ///< 0: consecutive poses (per scan)
  ErrorStats translation_m;
  ErrorStats rotation_rad;
};

/// RPE of `estimate` against `reference` at one pair spacing.
RpeResult ComputeRpe(const Trajectory& estimate, const Trajectory& reference, double distance_m,
                     const AssociationOptions& options = {});

}  // namespace slamrig::slam
