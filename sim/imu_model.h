#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/mount_pose.h"
#include "slam/types/random_stream.h"
#include "slam/types/records.h"

namespace slamrig::sim {

/// Noise of one IMU sensor triad, per axis, in the continuous-time parameters that Gazebo and
/// Kalibr use. Units: for the gyro rad/s, for the accelerometer m/s^2 ("unit" below).
struct ImuNoise {
  double noise_density = 0.0;        ///< white noise, unit / sqrt(Hz)
  double random_walk = 0.0;          ///< bias random walk, unit / s / sqrt(Hz)
  double bias = 0.0;                 ///< constant bias, unit
  double turn_on_bias_stddev = 0.0;  ///< a bias drawn once per run per axis, unit
  double scale_error = 0.0;          ///< measured = (1 + scale_error) * true + ...
  double saturation = 0.0;           ///< |measured| is clipped to this; 0: no limit

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// A 6-axis MEMS IMU at the robot's base (aligned with base_link, REP-145 gravity convention: at
/// rest the accelerometer reads +g on z). Defaults are the ADIS16448 figures of the EuRoC dataset
/// with a consumer-grade turn-on bias and scale error.
struct ImuOptions {
  bool enabled = true;            ///< false: the robot has no IMU
  double rate_hz = 100.0;         ///< samples per second
  MountPose mount;                ///< position on the robot (yaw must be 0: axes as base_link)
  double gravity_m_s2 = 9.80665;  ///< what the accelerometer z reads at rest
  ImuNoise gyro{1.6968e-4, 1.9393e-5, 0.0, 0.002, 0.003, 8.7266};  ///< rad/s; 500 deg/s range
  ImuNoise accel{2.0e-3, 3.0e-3, 0.0, 0.05, 0.005, 39.2266};       ///< m/s^2; 4 g range

  /// One message per broken rule, e.g. "gyro.noise_density = -1; must be >= 0".
  std::vector<std::string> Validate() const;
};

/// Adds IMU errors to true rates and specific forces: measured = (1 + scale) * true + constant
/// bias + turn-on bias + random-walk bias + white noise, then saturated. Discrete-time noise
/// follows the continuous parameters (white: density * sqrt(rate); walk: random_walk /
/// sqrt(rate) per sample), as in Gazebo's ImuSensor and Kalibr's IMU noise model.
class ImuModel {
 public:
  /// `options` must be valid (checked). Draws from the streams "imu.gyro" and "imu.accel".
  ImuModel(const ImuOptions& options, std::uint64_t seed);

  /// The sample at `time` for a true angular velocity (rad/s) and a true specific force (m/s^2),
  /// both in the IMU frame. Call once per sample period, in time order.
  ImuSample Measure(Time time, const Eigen::Vector3d& true_rate_rad_s,
                    const Eigen::Vector3d& true_specific_force_m_s2);

  /// The options it was built with.
  const ImuOptions& options() const { return options_; }

 private:
  struct Triad {
    ImuNoise noise;
    RandomStream rng;
    Eigen::Vector3d turn_on_bias = Eigen::Vector3d::Zero();
    Eigen::Vector3d walk_bias = Eigen::Vector3d::Zero();
  };
  Eigen::Vector3d Apply(Triad* triad, const Eigen::Vector3d& truth);

  ImuOptions options_;
  Triad gyro_;
  Triad accel_;
};

}  // namespace slamrig::sim
