#pragma once

#include "slam/types/pose2.h"

namespace slamrig::sim {

/// Where a sensor sits on the robot: base_from_sensor as plain fields (x forward, y left).
struct MountPose {
  double x_m = 0.0;      ///< forward of base_link
  double y_m = 0.0;      ///< left of base_link
  double yaw_rad = 0.0;  ///< CCW from base_link's x axis

  /// The same mounting as an SE(2) transform base_from_sensor.
  Pose2 ToPose2() const { return Pose2(x_m, y_m, yaw_rad); }
};

/// Fields of a mounting pose (also used for the spawn pose); see slam/config/fields.h.
template <typename V>
void VisitFields(V& v, MountPose& m) {
  v("x_m", m.x_m);
  v("y_m", m.y_m);
  v("yaw_rad", m.yaw_rad);
}

}  // namespace slamrig::sim
