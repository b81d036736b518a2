#include "slam/fusion/pose_ekf_options.h"

#include <utility>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> PoseEkfOptions::Validate() const {
  Rules rules;
  rules.NonNegative("encoder_sigma_rel", encoder_sigma_rel)
      .NonNegative("encoder_lateral_sigma_rel", encoder_lateral_sigma_rel)
      .NonNegative("encoder_yaw_sigma_rel", encoder_yaw_sigma_rel)
      .NonNegative("encoder_skid_sigma_m_per_sqrt_rad", encoder_skid_sigma_m_per_sqrt_rad)
      .NonNegative("encoder_slip_share", encoder_slip_share)
      .NonNegative("gyro_sigma_rad_s", gyro_sigma_rad_s)
      .NonNegative("gyro_bias_sigma_rad_s", gyro_bias_sigma_rad_s)
      .NonNegative("gyro_bias_walk_rad_s_sqrt_s", gyro_bias_walk_rad_s_sqrt_s)
      .NonNegative("gyro_scale_sigma", gyro_scale_sigma)
      .NonNegative("increment_sigma_xy_per_m", increment_sigma_xy_per_m)
      .NonNegative("increment_sigma_xy_floor_m", increment_sigma_xy_floor_m)
      .NonNegative("increment_sigma_yaw_per_rad", increment_sigma_yaw_per_rad)
      .NonNegative("increment_sigma_yaw_per_m", increment_sigma_yaw_per_m)
      .NonNegative("increment_sigma_yaw_floor_rad", increment_sigma_yaw_floor_rad);
  return rules.errors();
}

}  // namespace slamrig::slam
