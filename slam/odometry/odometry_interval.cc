#include "slam/odometry/odometry_interval.h"

#include "slam/odometry/wheel_odometry.h"
#include "slam/types/check.h"

namespace slamrig::slam {
double MeanTicks(const std::vector<std::int32_t>& ticks) {
  if (ticks.empty()) return 0.0;
  double sum = 0.0;
  for (const std::int32_t t : ticks) sum += t;
  return sum / static_cast<double>(ticks.size());
}

void OdometryInterval::AddTicks(const WheelTicks& ticks) {
  SLAMRIG_CHECK(!ticks.right_ticks.empty() && !ticks.left_ticks.empty(),
                "WheelTicks needs at least one wheel per side");
  right_ticks_ += MeanTicks(ticks.right_ticks);
  left_ticks_ += MeanTicks(ticks.left_ticks);
  has_ticks_ = true;
}

OdometryInterval::Motion OdometryInterval::Take(const DiffDriveParams& robot, double dt_s,
                                                bool use_gyro, std::optional<double>* held_rate) {
  const double metres_per_tick = robot.MetresPerTick();
  const double right_m = right_ticks_ * metres_per_tick;
  const double left_m = left_ticks_ * metres_per_tick;
  Motion motion;
  motion.distance_m = 0.5 * (right_m + left_m);
  motion.yaw_rad = (right_m - left_m) / robot.track_width_m;
  if (use_gyro) {
    if (gyro_count_ > 0) {
      const double rate = gyro_sum_rad_s_ / gyro_count_;
      if (held_rate != nullptr) *held_rate = rate;
      motion.yaw_rad = rate * dt_s;
    } else {
      motion.gyro_fallback = true;
      if (held_rate != nullptr && *held_rate) motion.yaw_rad = **held_rate * dt_s;
    }
  }
  Clear();
  return motion;
}

void OdometryInterval::Clear() {
  right_ticks_ = left_ticks_ = gyro_sum_rad_s_ = 0.0;
  gyro_count_ = 0;
}

}  // namespace slamrig::slam
