#include "sim/robot_spec.h"

#include "slam/types/validation.h"

namespace slamrig::sim {
std::vector<std::string> ChassisOptions::Validate() const {
  Rules rules;
  rules.Positive("mass_kg", mass_kg).Positive("length_m", length_m).Positive("width_m", width_m);
  rules.NonNegative("yaw_inertia_kg_m2", yaw_inertia_kg_m2)
      .NonNegative("wall_friction", wall_friction);
  return rules.errors();
}

std::vector<std::string> WheelOptions::Validate() const {
  Rules rules;
  rules.Positive("radius_m", radius_m)
      .Positive("track_width_m", track_width_m)
      .InRange("per_side", per_side, 1, 4);
  if (per_side > 1) rules.Positive("wheelbase_m", wheelbase_m);
  rules.Require(per_side != 1 || wheelbase_m == 0.0, "wheelbase_m", wheelbase_m,
                "must be 0 with one wheel per side");
  rules.Positive("spin_inertia_kg_m2", spin_inertia_kg_m2)
      .InRange("caster_load_fraction", caster_load_fraction, 0.0, 1.0, Ends::kOpenHigh)
      .Positive("contact_stiffness_per_m", contact_stiffness_per_m)
      .Positive("relaxation_length_m", relaxation_length_m)
      .Positive("contact_damping_s_m", contact_damping_s_m);
  return rules.errors();
}

std::vector<std::string> MotorOptions::Validate() const {
  Rules rules;
  rules.Positive("max_torque_n_m", max_torque_n_m)
      .NonNegative("kp_n_m_s_rad", kp_n_m_s_rad)
      .NonNegative("ki_n_m_rad", ki_n_m_rad)
      .Positive("max_wheel_speed_rad_s", max_wheel_speed_rad_s);
  return rules.errors();
}

std::vector<std::string> CalibrationErrors::Validate() const {
  Rules rules;
  rules.InRange("left_radius_error", left_radius_error, -0.5, 0.5, Ends::kOpen)
      .InRange("right_radius_error", right_radius_error, -0.5, 0.5, Ends::kOpen)
      .InRange("track_width_error", track_width_error, -0.5, 0.5, Ends::kOpen);
  return rules.errors();
}

std::vector<std::string> MotionLimits::Validate() const {
  Rules rules;
  rules.Positive("max_speed_m_s", max_speed_m_s)
      .Positive("max_accel_m_s2", max_accel_m_s2)
      .Positive("max_yaw_rate_rad_s", max_yaw_rate_rad_s)
      .Positive("max_yaw_accel_rad_s2", max_yaw_accel_rad_s2);
  return rules.errors();
}

std::vector<std::string> RobotSpec::Validate() const {
  Rules rules;
  rules.Nested("chassis", chassis.Validate())
      .Nested("wheels", wheels.Validate())
      .Nested("motor", motor.Validate())
      .Nested("calibration", calibration.Validate())
      .Nested("limits", limits.Validate())
      .Nested("encoders", encoders.Validate())
      .Nested("imu", imu.Validate())
      .Nested("lidar", lidar.Validate());
  if (camera) rules.Nested("camera", camera->Validate());
  return rules.errors();
}

RobotSpec WithoutNoise(RobotSpec spec) {
  spec.calibration = CalibrationErrors{0.0, 0.0, 0.0};
  spec.encoders.slip_stddev = 0.0;
  spec.encoders.slip_common_stddev = 0.0;
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
