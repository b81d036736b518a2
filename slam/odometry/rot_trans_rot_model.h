#pragma once

#include <string>
#include <vector>

#include "slam/odometry/gaussian.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// An odometry increment as rotation, translation, rotation (Thrun, Burgard, Fox, "Probabilistic
/// Robotics", Sec. 5.4; the guide in references/003, "Rotation-translation-rotation model").
/// A backward motion has a negative `trans_m` so that `rot1_rad` stays small.
struct RotTransRot {
  double rot1_rad = 0.0;
  double trans_m = 0.0;
  double rot2_rad = 0.0;

  /// Decomposes the robot-frame increment `before_from_after`.
  static RotTransRot FromIncrement(const Pose2& before_from_after);
  /// The robot-frame increment this motion produces.
  Pose2 ToIncrement() const;
};

/// The alpha noise parameters of the odometry motion model (Probabilistic Robotics, Table 5.6):
/// variances rot1: a1 rot1^2 + a2 trans^2, trans: a3 trans^2 + a4 (rot1^2 + rot2^2),
/// rot2: a1 rot2^2 + a2 trans^2; plus small floors so a standing robot still diffuses a little.
struct RotTransRotNoise {
  double alpha1 = 0.05;            ///< rotation variance per rotation^2, rad^2/rad^2
  double alpha2 = 0.001;           ///< rotation variance per translation^2, rad^2/m^2
  double alpha3 = 0.01;            ///< translation variance per translation^2, m^2/m^2
  double alpha4 = 0.001;           ///< translation variance per rotation^2, m^2/rad^2
  double min_trans_sigma_m = 0.0;  ///< standard deviation floor on the translation
  double min_rot_sigma_rad = 0.0;  ///< standard deviation floor on each rotation

  /// One message per broken rule, e.g. "rot_trans_rot.alpha1 = -1; must be >= 0".
  std::vector<std::string> Validate() const;
};

/// The field table of RotTransRotNoise (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, RotTransRotNoise& o) {
  v("alpha1", o.alpha1);
  v("alpha2", o.alpha2);
  v("alpha3", o.alpha3);
  v("alpha4", o.alpha4);
  v("min_trans_sigma_m", o.min_trans_sigma_m);
  v("min_rot_sigma_rad", o.min_rot_sigma_rad);
}

/// Draws a noisy version of the robot-frame increment `before_from_after` (Table 5.6).
Pose2 SampleRotTransRot(const Pose2& before_from_after, const RotTransRotNoise& noise,
                        RandomEngine& rng);

}  // namespace slamrig::slam
