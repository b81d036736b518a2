#pragma once

#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// An estimated pose and the reference pose at the same time.
struct PosePair {
  Time time;
  Pose2 estimate;
  Pose2 reference;
};

/// How estimate and reference poses are paired.
struct AssociationOptions {
  /// Interpolate the reference only between samples at most this far apart in time, seconds.
  double max_interpolation_gap_s = 1.0;
};

/// Pairs every estimate pose with the reference at its time. When both trajectories have the
/// same stamps in the same order (one pose per scan of the same log, repeated stamps included),
/// poses are paired by index; otherwise the reference is interpolated at each estimate time, and
/// estimate poses outside the reference span or in a gap longer than the limit are left out.
std::vector<PosePair> AssociatePoses(const Trajectory& estimate, const Trajectory& reference,
                                     const AssociationOptions& options = {});

/// The rigid transform reference_from_estimate minimising the summed squared position error of
/// the pairs (closed-form 2D Horn/Umeyama without scale). Identity for fewer than two pairs.
Pose2 AlignSE2(const std::vector<PosePair>& pairs);

}  // namespace slamrig::slam
