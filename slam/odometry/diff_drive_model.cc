// Differential-drive kinematics, discretised two ways:
//  - exact arc: Wang, "Simultaneous Localization and Mapping with Texture" (ECE276A), Eq. 6,
//    x' = x + v tau sinc(w tau / 2) cos(theta + w tau / 2), same for y with sin, theta' = theta + w
//    tau;
//  - Euler: Kansal, "Particle Filter SLAM and Texture Mapping" (ECE276A), Sec. III-A.
#include "slam/odometry/diff_drive_model.h"

namespace slamrig::slam {

Pose2 DiffDriveIncrement(double distance_m, double yaw_change_rad,
                         DiffDriveIntegration integration) {
  if (integration == DiffDriveIntegration::kEuler) {
    return Pose2(distance_m, 0.0, yaw_change_rad);
  }
  return ArcIncrement(distance_m, yaw_change_rad);
}

Pose2 IntegrateDiffDrive(const Pose2& world_from_base, double distance_m, double yaw_change_rad,
                         DiffDriveIntegration integration) {
  return world_from_base * DiffDriveIncrement(distance_m, yaw_change_rad, integration);
}

}  // namespace slamrig::slam
