#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sim/camera_spec.h"
#include "sim/encoder_model.h"
#include "sim/imu_model.h"
#include "sim/lidar_model.h"
#include "slam/odometry/wheel_odometry.h"

namespace slamrig::sim {

/// The rigid body of the robot: a box footprint centred on base_link, centre of mass there.
struct ChassisOptions {
  double mass_kg = 8.0;            ///< total mass, wheels included
  double length_m = 0.55;          ///< footprint along x
  double width_m = 0.50;           ///< footprint along y
  double yaw_inertia_kg_m2 = 0.0;  ///< about the centre of mass; 0: a uniform box's
  double wall_friction = 0.3;      ///< Coulomb friction of the bumper against walls

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// Wheel layout and tyre. The radius and track are the nominal values the robot's own software
/// believes; the physical ones differ by CalibrationErrors.
struct WheelOptions {
  double radius_m = 0.127;            ///< nominal wheel radius
  double track_width_m = 0.3937;      ///< nominal distance between left and right contacts
  int per_side = 2;                   ///< driven wheels on each side, each with its own motor
  double wheelbase_m = 0.3302;        ///< front to rear wheel distance (per_side > 1)
  double spin_inertia_kg_m2 = 0.02;   ///< wheel plus motor and gearbox reflected to the axle
  double caster_load_fraction = 0.0;  ///< share of the weight on passive casters
  /// Tyre contact: the tread deflects like a spring (force / load per metre of deflection), the
  /// deflection relaxes as the tread rolls out of the contact patch (over the relaxation length),
  /// and a damper acts on the slip velocity (force / load per m/s). Rolling under traction thus
  /// slips in proportion to speed (a slip ratio), a stalled wheel holds without creeping, and the
  /// force never exceeds mu * load.
  double contact_stiffness_per_m = 500.0;  ///< 1/m: at mu 0.8 the tread slides at 1.6 mm
  double relaxation_length_m = 0.03;       ///< m, about a contact patch length
  double contact_damping_s_m = 30.0;       ///< s/m

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// A DC motor per wheel with a PI speed loop on the wheel's spin rate.
struct MotorOptions {
  double max_torque_n_m = 4.0;          ///< at the wheel axle, both directions
  double kp_n_m_s_rad = 1.5;            ///< proportional gain, N m per rad/s of speed error
  double ki_n_m_rad = 10.0;             ///< integral gain, N m per rad of accumulated error
  double max_wheel_speed_rad_s = 20.0;  ///< the speed loop never asks for more

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// How the physical robot differs from its nominal parameters: true = nominal * (1 + error).
struct CalibrationErrors {
  double left_radius_error = 0.003;    ///< relative error of the left wheels' radius
  double right_radius_error = -0.002;  ///< relative error of the right wheels' radius
  double track_width_error = 0.0;      ///< relative error of the track width

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// Velocity ramps the robot's base controller applies to incoming (v, omega) commands.
struct MotionLimits {
  double max_speed_m_s = 1.0;         ///< commands are clipped to this speed
  double max_accel_m_s2 = 1.0;        ///< speed ramp
  double max_yaw_rate_rad_s = 2.0;    ///< commands are clipped to this yaw rate
  double max_yaw_accel_rad_s2 = 4.0;  ///< yaw rate ramp

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// A complete robot preset (robots/*.yaml): body, wheels, motors, calibration and sensors.
/// The default is the ECE276A robot.
struct RobotSpec {
  std::string name = "ece276a";   ///< written into logs and reports
  ChassisOptions chassis;         ///< body
  WheelOptions wheels;            ///< layout and tyres
  MotorOptions motor;             ///< one per wheel
  CalibrationErrors calibration;  ///< physical versus nominal geometry
  MotionLimits limits;            ///< base controller ramps
  EncoderOptions encoders;        ///< wheel encoders
  ImuOptions imu;                 ///< inertial sensor
  LidarOptions lidar;             ///< 2D range finder
  /// An RGB-D camera (sim/camera renders it; the Simulator itself ignores it); none if absent.
  std::optional<CameraSpec> camera;

  /// One message per broken rule, field names as in the robot file ("motor.kp_n_m_s_rad = ...").
  std::vector<std::string> Validate() const;
};

/// The nominal wheel geometry the robot's own odometry (and SLAM) integrates the encoder ticks
/// with: wheel radius, ticks per revolution and track width as specified, without the
/// calibration errors only the simulator knows.
slam::DiffDriveParams NominalOdometry(const RobotSpec& spec);

/// `spec` with every noise source and calibration error switched off: no IMU noise, bias or
/// scale error, no lidar noise or mixture outliers, no range rounding, no random encoder slip,
/// nominal = physical geometry.
/// Tick quantization and the physics (slip, skid) remain.
RobotSpec WithoutNoise(RobotSpec spec);

}  // namespace slamrig::sim
