#include "sim/imu_model.h"

#include <algorithm>
#include <cmath>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> ImuNoise::Validate() const {
  std::vector<std::string> errors;
  for (const auto& [name, value] :
       {std::pair{"noise_density", noise_density}, std::pair{"random_walk", random_walk},
        std::pair{"turn_on_bias_stddev", turn_on_bias_stddev},
        std::pair{"saturation", saturation}}) {
    if (!(value >= 0.0))
      errors.push_back(std::string(name) + " = " + FormatNumber(value) + "; must be >= 0");
  }
  if (!(scale_error > -1.0)) {
    errors.push_back("scale_error = " + FormatNumber(scale_error) + "; must be > -1");
  }
  return errors;
}

std::vector<std::string> ImuOptions::Validate() const {
  std::vector<std::string> errors;
  if (!(rate_hz > 0.0 && rate_hz <= 10000.0)) {
    errors.push_back("rate_hz = " + FormatNumber(rate_hz) + "; must be in (0, 10000]");
  }
  if (mount.yaw_rad != 0.0) {
    errors.push_back("mount.yaw_rad = " + FormatNumber(mount.yaw_rad) +
                     "; the IMU axes must be base_link's (0)");
  }
  if (!(gravity_m_s2 >= 0.0))
    errors.push_back("gravity_m_s2 = " + FormatNumber(gravity_m_s2) + "; must be >= 0");
  AppendErrors(&errors, PrefixErrors("gyro", gyro.Validate()));
  AppendErrors(&errors, PrefixErrors("accel", accel.Validate()));
  return errors;
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
