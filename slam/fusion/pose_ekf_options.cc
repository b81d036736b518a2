#include "slam/fusion/pose_ekf_options.h"

#include <utility>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> PoseEkfOptions::Validate() const {
  std::vector<std::string> errors;
  const std::pair<const char*, double> non_negative[] = {
      {"encoder_sigma_rel", encoder_sigma_rel},
      {"encoder_lateral_sigma_rel", encoder_lateral_sigma_rel},
      {"encoder_yaw_sigma_rel", encoder_yaw_sigma_rel},
      {"encoder_skid_sigma_m_per_sqrt_rad", encoder_skid_sigma_m_per_sqrt_rad},
      {"encoder_slip_share", encoder_slip_share},
      {"gyro_sigma_rad_s", gyro_sigma_rad_s},
      {"gyro_bias_sigma_rad_s", gyro_bias_sigma_rad_s},
      {"gyro_bias_walk_rad_s_sqrt_s", gyro_bias_walk_rad_s_sqrt_s},
      {"gyro_scale_sigma", gyro_scale_sigma},
      {"increment_sigma_xy_per_m", increment_sigma_xy_per_m},
      {"increment_sigma_xy_floor_m", increment_sigma_xy_floor_m},
      {"increment_sigma_yaw_per_rad", increment_sigma_yaw_per_rad},
      {"increment_sigma_yaw_per_m", increment_sigma_yaw_per_m},
      {"increment_sigma_yaw_floor_rad", increment_sigma_yaw_floor_rad},
  };
  for (const auto& [name, value] : non_negative) {
    if (!(value >= 0.0)) errors.push_back(RuleViolation(name, value, "must be >= 0"));
  }
  return errors;
}

}  // namespace slamrig::slam
