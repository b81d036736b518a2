#include "sim/robot_spec.h"

#include "slam/types/validation.h"

namespace slamrig::sim {
namespace {

void RequirePositive(std::vector<std::string>* errors, const char* name, double value) {
  if (!(value > 0.0))
    errors->push_back(std::string(name) + " = " + FormatNumber(value) + "; must be > 0");
}

void RequireNonNegative(std::vector<std::string>* errors, const char* name, double value) {
  if (!(value >= 0.0)) {
    errors->push_back(std::string(name) + " = " + FormatNumber(value) + "; must be >= 0");
  }
}

}  // namespace

std::vector<std::string> ChassisOptions::Validate() const {
  std::vector<std::string> errors;
  RequirePositive(&errors, "mass_kg", mass_kg);
  RequirePositive(&errors, "length_m", length_m);
  RequirePositive(&errors, "width_m", width_m);
  RequireNonNegative(&errors, "yaw_inertia_kg_m2", yaw_inertia_kg_m2);
  RequireNonNegative(&errors, "wall_friction", wall_friction);
  return errors;
}

std::vector<std::string> WheelOptions::Validate() const {
  std::vector<std::string> errors;
  RequirePositive(&errors, "radius_m", radius_m);
  RequirePositive(&errors, "track_width_m", track_width_m);
  if (per_side < 1 || per_side > 4) {
    errors.push_back("per_side = " + std::to_string(per_side) + "; must be in [1, 4]");
  }
  if (per_side > 1) RequirePositive(&errors, "wheelbase_m", wheelbase_m);
  if (per_side == 1 && wheelbase_m != 0.0) {
    errors.push_back("wheelbase_m = " + FormatNumber(wheelbase_m) +
                     "; must be 0 with one wheel per side");
  }
  RequirePositive(&errors, "spin_inertia_kg_m2", spin_inertia_kg_m2);
  if (!(caster_load_fraction >= 0.0 && caster_load_fraction < 1.0)) {
    errors.push_back("caster_load_fraction = " + FormatNumber(caster_load_fraction) +
                     "; must be in [0, 1)");
  }
  RequirePositive(&errors, "contact_stiffness_per_m", contact_stiffness_per_m);
  RequirePositive(&errors, "relaxation_length_m", relaxation_length_m);
  RequirePositive(&errors, "contact_damping_s_m", contact_damping_s_m);
  return errors;
}

std::vector<std::string> MotorOptions::Validate() const {
  std::vector<std::string> errors;
  RequirePositive(&errors, "max_torque_n_m", max_torque_n_m);
  RequireNonNegative(&errors, "kp_n_m_s_rad", kp_n_m_s_rad);
  RequireNonNegative(&errors, "ki_n_m_rad", ki_n_m_rad);
  RequirePositive(&errors, "max_wheel_speed_rad_s", max_wheel_speed_rad_s);
  return errors;
}

std::vector<std::string> CalibrationErrors::Validate() const {
  std::vector<std::string> errors;
  for (const auto& [name, value] : {std::pair{"left_radius_error", left_radius_error},
                                    std::pair{"right_radius_error", right_radius_error},
                                    std::pair{"track_width_error", track_width_error}}) {
    if (!(value > -0.5 && value < 0.5)) {
      errors.push_back(std::string(name) + " = " + FormatNumber(value) +
                       "; must be in (-0.5, 0.5)");
    }
  }
  return errors;
}

std::vector<std::string> MotionLimits::Validate() const {
  std::vector<std::string> errors;
  RequirePositive(&errors, "max_speed_m_s", max_speed_m_s);
  RequirePositive(&errors, "max_accel_m_s2", max_accel_m_s2);
  RequirePositive(&errors, "max_yaw_rate_rad_s", max_yaw_rate_rad_s);
  RequirePositive(&errors, "max_yaw_accel_rad_s2", max_yaw_accel_rad_s2);
  return errors;
}

std::vector<std::string> RobotSpec::Validate() const {
  std::vector<std::string> errors;
  AppendErrors(&errors, PrefixErrors("chassis", chassis.Validate()));
  AppendErrors(&errors, PrefixErrors("wheels", wheels.Validate()));
  AppendErrors(&errors, PrefixErrors("motor", motor.Validate()));
  AppendErrors(&errors, PrefixErrors("calibration", calibration.Validate()));
  AppendErrors(&errors, PrefixErrors("limits", limits.Validate()));
  AppendErrors(&errors, PrefixErrors("encoders", encoders.Validate()));
  AppendErrors(&errors, PrefixErrors("imu", imu.Validate()));
  AppendErrors(&errors, PrefixErrors("lidar", lidar.Validate()));
  if (camera) AppendErrors(&errors, PrefixErrors("camera", camera->Validate()));
  return errors;
}

RobotSpec WithoutNoise(RobotSpec spec) {
  spec.calibration = CalibrationErrors{0.0, 0.0, 0.0};
  spec.imu.gyro = ImuNoise{};
  spec.imu.accel = ImuNoise{};
  spec.lidar.range_noise_stddev_m = 0.0;
  spec.lidar.range_noise_fraction = 0.0;
  spec.lidar.range_resolution_m = 0.0;
  spec.lidar.p_short = 0.0;
  spec.lidar.p_max = 0.0;
  spec.lidar.p_random = 0.0;
  return spec;
}

slam::DiffDriveParams NominalOdometry(const RobotSpec& spec) {
  slam::DiffDriveParams params;
  params.wheel_radius_m = spec.wheels.radius_m;
  params.ticks_per_revolution = spec.encoders.ticks_per_revolution;
  params.track_width_m = spec.wheels.track_width_m;
  return params;
}

}  // namespace slamrig::sim
