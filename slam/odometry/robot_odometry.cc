#include "slam/odometry/robot_odometry.h"

namespace slamrig::slam {

std::optional<OdometryPose> RobotOdometry::Add(const Record& record) {
  if (const auto* imu = std::get_if<ImuSample>(&record)) {
    odometry_.AddImu(*imu);
    ++imu_samples_;
    return std::nullopt;
  }
  if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
    ++poses_;
    return odometry_.AddTicks(*ticks);
  }
  if (const auto* pose = std::get_if<OdometryPose>(&record)) {
    ++poses_;
    return *pose;
  }
  return std::nullopt;
}

}  // namespace slamrig::slam
