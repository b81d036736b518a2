#include "sim/imu_model.h"

#include <algorithm>
#include <cmath>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> ImuNoise::Validate() const {
  Rules rules;
  rules.NonNegative("noise_density", noise_density)
      .NonNegative("random_walk", random_walk)
      .NonNegative("turn_on_bias_stddev", turn_on_bias_stddev)
      .NonNegative("saturation", saturation)
      .Above("scale_error", scale_error, -1.0);
  return rules.errors();
}

std::vector<std::string> ImuOptions::Validate() const {
  Rules rules;
  rules.InRange("rate_hz", rate_hz, 0.0, 10000.0, Ends::kOpenLow)
      .Require(mount.yaw_rad == 0.0, "mount.yaw_rad", mount.yaw_rad,
               "the IMU axes must be base_link's (0)")
      .NonNegative("gravity_m_s2", gravity_m_s2)
      .Nested("gyro", gyro.Validate())
      .Nested("accel", accel.Validate());
  return rules.errors();
}

ImuModel::ImuModel(const ImuOptions& options, std::uint64_t seed)
    : options_(options),
      gyro_{options.gyro, RandomStream(seed, "imu.gyro")},
      accel_{options.accel, RandomStream(seed, "imu.accel")} {
  SLAMRIG_CHECK_VALID(options_, "ImuOptions");
  for (Triad* triad : {&gyro_, &accel_}) {
    for (int axis = 0; axis < 3; ++axis) {
      triad->turn_on_bias[axis] = triad->noise.turn_on_bias_stddev * triad->rng.Gaussian();
    }
  }
}

Eigen::Vector3d ImuModel::Apply(Triad* triad, const Eigen::Vector3d& truth) {
  const ImuNoise& n = triad->noise;
  const double white_stddev = n.noise_density * std::sqrt(options_.rate_hz);
  const double walk_stddev = n.random_walk / std::sqrt(options_.rate_hz);
  Eigen::Vector3d measured;
  for (int axis = 0; axis < 3; ++axis) {
    if (walk_stddev > 0.0) triad->walk_bias[axis] += walk_stddev * triad->rng.Gaussian();
    double value = (1.0 + n.scale_error) * truth[axis] + n.bias + triad->turn_on_bias[axis] +
                   triad->walk_bias[axis];
    if (white_stddev > 0.0) value += white_stddev * triad->rng.Gaussian();
    if (n.saturation > 0.0) value = std::clamp(value, -n.saturation, n.saturation);
    measured[axis] = value;
  }
  return measured;
}

ImuSample ImuModel::Measure(Time time, const Eigen::Vector3d& true_rate_rad_s,
                            const Eigen::Vector3d& true_specific_force_m_s2) {
  ImuSample sample;
  sample.time = time;
  sample.angular_velocity_rad_s = Apply(&gyro_, true_rate_rad_s);
  sample.linear_acceleration_m_s2 = Apply(&accel_, true_specific_force_m_s2);
  return sample;
}

}  // namespace slamrig::sim
