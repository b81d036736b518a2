#pragma once

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// How a differential-drive step (travelled distance, yaw change) is discretised.
enum class DiffDriveIntegration {
  /// Exact constant-curvature arc: the chord is distance * sinc(dyaw / 2) along the mean heading
  /// theta + dyaw / 2 (Wang, ECE276A report, Eq. 6; Zafari, Eq. 1).
  kExactArc,
  /// First-order Euler step along the initial heading (Kansal, ECE276A report, Sec. III-A).
  kEuler,
};

/// Moves `world_from_base` by `distance_m` along the robot's x axis while its heading changes by
/// `yaw_change_rad`. For a velocity input (v, omega) over tau seconds pass v * tau and omega * tau.
Pose2 IntegrateDiffDrive(const Pose2& world_from_base, double distance_m, double yaw_change_rad,
                         DiffDriveIntegration integration = DiffDriveIntegration::kExactArc);

/// The same step as a robot-frame increment base_before_from_base_after (x forward, y left).
Pose2 DiffDriveIncrement(double distance_m, double yaw_change_rad,
                         DiffDriveIntegration integration = DiffDriveIntegration::kExactArc);

}  // namespace slamrig::slam
