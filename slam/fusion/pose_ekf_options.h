#pragma once

#include <string>
#include <vector>

namespace slamrig::slam {

/// Noise of PoseEkf's motion and bias models. Standard deviations; units in the names.
struct PoseEkfOptions {
  /// Travelled distance per encoder interval: sigma = encoder_sigma_rel * |distance|.
  double encoder_sigma_rel = 0.02;
  /// Sideways slip per encoder interval: sigma = encoder_lateral_sigma_rel * |distance|.
  double encoder_lateral_sigma_rel = 0.01;
  /// Skid of a skid-steered base while it turns: a random walk of the position with the yaw
  /// turned, variance encoder_skid_sigma_m_per_sqrt_rad^2 * |yaw turned| in x and in y (the
  /// turn's instantaneous centre wanders along the wheelbase as the wheels' loads shift, so the
  /// base moves by that offset times the angle even on a turn in place, where the distance terms
  /// add nothing). Per radian, not per interval, so that it does not depend on the encoder rate.
  double encoder_skid_sigma_m_per_sqrt_rad = 0.0;
  /// Wheel slip the gyro sees (WheelSlipDetector: the wheels' differential beyond the base's
  /// usual skid ratio) moves the base by this share of it (standard deviation, in x and in y,
  /// coherent over the detector's window). The common-mode slip that corrupts the distance is
  /// unobserved, but it comes with the differential one: a differential slip d split between
  /// the sides in an unknown proportion, uniform, leaves a common part of standard deviation
  /// d / (2 sqrt 3) = 0.29 d. (On the office's ice, seed 1, tick by tick against the truth, the
  /// distance erred by 0.1 to 0.7 of the differential slip per half second.) 0: off.
  double encoder_slip_share = 0.2887;
  /// Yaw from the wheel difference (no gyro in the interval): sigma = rel * (|right| + |left|) /
  /// track width.
  double encoder_yaw_sigma_rel = 0.02;
  /// White noise of one gyro z sample, rad/s; a sample held over dt adds (sigma * dt)^2.
  double gyro_sigma_rad_s = 0.01;
  /// Prior standard deviation of the gyro bias at the start, rad/s.
  double gyro_bias_sigma_rad_s = 0.01;
  /// Prior standard deviation of the gyro's scale error (relative: 0.003 is 0.3 %); estimated,
  /// so that a turn's extra or missing yaw is not taken for a bias.
  double gyro_scale_sigma = 0.005;
  /// Random walk of the gyro bias, rad/s per sqrt(s).
  double gyro_bias_walk_rad_s_sqrt_s = 1e-4;
  /// Odometry-pose increments (logs without encoders): sigma_xy = per_m * distance + floor,
  /// sigma_yaw = per_rad * |turn| + per_m * distance + floor.
  double increment_sigma_xy_per_m = 0.05;
  double increment_sigma_xy_floor_m = 0.002;
  double increment_sigma_yaw_per_rad = 0.05;
  double increment_sigma_yaw_per_m = 0.02;
  double increment_sigma_yaw_floor_rad = 0.001;
  /// A gyro sample taken while the encoders report no motion measures the bias (a zero-velocity
  /// update).
  bool zero_rate_updates = true;

  /// One message per broken rule ("gyro_sigma_rad_s = -1; must be >= 0").
  std::vector<std::string> Validate() const;
};

/// The field table of PoseEkfOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, PoseEkfOptions& o) {
  v("encoder_sigma_rel", o.encoder_sigma_rel);
  v("encoder_lateral_sigma_rel", o.encoder_lateral_sigma_rel);
  v("encoder_yaw_sigma_rel", o.encoder_yaw_sigma_rel);
  v("encoder_skid_sigma_m_per_sqrt_rad", o.encoder_skid_sigma_m_per_sqrt_rad);
  v("encoder_slip_share", o.encoder_slip_share);
  v("gyro_sigma_rad_s", o.gyro_sigma_rad_s);
  v("gyro_bias_sigma_rad_s", o.gyro_bias_sigma_rad_s);
  v("gyro_bias_walk_rad_s_sqrt_s", o.gyro_bias_walk_rad_s_sqrt_s);
  v("gyro_scale_sigma", o.gyro_scale_sigma);
  v("increment_sigma_xy_per_m", o.increment_sigma_xy_per_m);
  v("increment_sigma_xy_floor_m", o.increment_sigma_xy_floor_m);
  v("increment_sigma_yaw_per_rad", o.increment_sigma_yaw_per_rad);
  v("increment_sigma_yaw_per_m", o.increment_sigma_yaw_per_m);
  v("increment_sigma_yaw_floor_rad", o.increment_sigma_yaw_floor_rad);
  v("zero_rate_updates", o.zero_rate_updates);
}

}  // namespace slamrig::slam
