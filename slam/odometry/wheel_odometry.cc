// Encoder + gyro dead reckoning as in the ECE276A reports (Wang Sec. III-A, Zafari "Technical
// approach"): per side distance = mean wheel ticks * metres per tick, v from the mean of both
// sides, yaw change from the mean gyro rate over the interval, integrated with Eq. 6 (sinc term).
#include "slam/odometry/wheel_odometry.h"

#include <numbers>

#include "slam/odometry/diff_drive_model.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

double MeanTicks(const std::vector<std::int32_t>& ticks) {
  double sum = 0.0;
  for (const std::int32_t t : ticks) sum += t;
  return sum / static_cast<double>(ticks.size());
}

}  // namespace

double DiffDriveParams::MetresPerTick() const {
  return 2.0 * std::numbers::pi * wheel_radius_m / ticks_per_revolution;
}

std::vector<std::string> DiffDriveParams::Validate() const {
  std::vector<std::string> errors;
  if (!(wheel_radius_m > 0.0)) {
    errors.push_back(RuleViolation("diff_drive.wheel_radius_m", wheel_radius_m, "must be > 0"));
  }
  if (ticks_per_revolution <= 0) {
    errors.push_back(
        RuleViolation("diff_drive.ticks_per_revolution", ticks_per_revolution, "must be > 0"));
  }
  if (!(track_width_m > 0.0)) {
    errors.push_back(RuleViolation("diff_drive.track_width_m", track_width_m, "must be > 0"));
  }
  return errors;
}

std::vector<std::string> WheelOdometryOptions::Validate() const {
  std::vector<std::string> errors;
  for (const std::string& e : robot.Validate()) errors.push_back("wheel_odometry." + e);
  return errors;
}

WheelOdometry::WheelOdometry(const WheelOdometryOptions& options) : options_(options) {
  SLAMRIG_CHECK(options_.Validate().empty(), "invalid WheelOdometryOptions");
}

void WheelOdometry::AddImu(const ImuSample& imu) {
  // Samples at or before the last ticks belong to an interval already integrated.
  if (has_last_time_ && imu.time <= last_time_) return;
  gyro_sum_rad_s_ += imu.angular_velocity_rad_s.z();
  ++gyro_count_;
}

OdometryPose WheelOdometry::AddTicks(const WheelTicks& ticks) {
  SLAMRIG_CHECK(!ticks.right_ticks.empty() && !ticks.left_ticks.empty(),
                "WheelTicks needs at least one wheel per side");
  const double metres_per_tick = options_.robot.MetresPerTick();
  const double right_m = MeanTicks(ticks.right_ticks) * metres_per_tick;
  const double left_m = MeanTicks(ticks.left_ticks) * metres_per_tick;
  const double distance_m = 0.5 * (right_m + left_m);

  double yaw_change_rad = (right_m - left_m) / options_.robot.track_width_m;
  if (options_.use_gyro) {
    if (has_last_time_ && gyro_count_ > 0) {
      const double dt_s = SecondsBetween(ticks.time, last_time_);
      yaw_change_rad = gyro_sum_rad_s_ / gyro_count_ * dt_s;
    } else {
      ++gyro_fallbacks_;
    }
  }
  pose_ = IntegrateDiffDrive(pose_, distance_m, yaw_change_rad, DiffDriveIntegration::kExactArc);
  has_last_time_ = true;
  last_time_ = ticks.time;
  gyro_sum_rad_s_ = 0.0;
  gyro_count_ = 0;
  return OdometryPose{ticks.time, pose_};
}

}  // namespace slamrig::slam
