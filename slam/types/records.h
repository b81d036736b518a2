#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <variant>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/rgbd_frame.h"
#include "slam/types/time.h"

namespace slamrig {

/// The robot's motion while a scan sweeps: forward speed and yaw rate, taken as constant.
struct BaseVelocity {
  double forward_m_s = 0.0;
  double yaw_rate_rad_s = 0.0;
};

/// One sweep of a planar range finder (REP-117 semantics).
/// Beam i points at `angle_min_rad + i * angle_increment_rad` in the laser frame and was taken at
/// `time + i * time_increment_s`. A range outside [range_min_m, range_max_m) is "no return": it
/// carries no hit, and a mapper may only clear free space along it. Sources reject NaN ranges.
struct LaserScan {
  Time time;                         ///< time of beam 0
  double angle_min_rad = 0.0;        ///< angle of beam 0 in the laser frame, CCW from +x
  double angle_increment_rad = 0.0;  ///< angle step between beams (may be negative)
  double time_increment_s = 0.0;     ///< time step between beams (0: all beams at `time`)
  double range_min_m = 0.0;          ///< shorter readings are invalid
  double range_max_m = 0.0;          ///< readings at or beyond this are "no return"
  std::vector<float> ranges_m;       ///< one range per beam, metres
  Pose2 base_from_laser;             ///< mounting pose of the laser on the robot
  /// The base's velocity while the beams were taken, as the receiver estimates it: sources leave
  /// it zero and the scan synchroniser sets it from the odometry. With time_increment_s it moves
  /// beam i to SweepPose(i); zero keeps every beam at the pose of `time`.
  BaseVelocity sweep_velocity;

  /// Angle of beam `i` in the laser frame.
  double BeamAngle(std::size_t i) const {
    return angle_min_rad + static_cast<double>(i) * angle_increment_rad;
  }
  /// True when the beams were taken from a moving base (see SweepPose).
  bool Sweeps() const {
    return time_increment_s != 0.0 &&
           (sweep_velocity.forward_m_s != 0.0 || sweep_velocity.yaw_rate_rad_s != 0.0);
  }
  /// base_link at `time` from base_link when beam `i` was taken: the arc `sweep_velocity` drives
  /// in i * time_increment_s (the identity when the scan does not sweep). A point p seen from
  /// the base at beam i is SweepPose(i) * p in base_link at `time`.
  Pose2 SweepPose(std::size_t i) const {
    const double t = static_cast<double>(i) * time_increment_s;
    return ArcIncrement(sweep_velocity.forward_m_s * t, sweep_velocity.yaw_rate_rad_s * t);
  }
  /// True if beam `i` is a real return (a hit on an obstacle).
  bool IsHit(std::size_t i) const {
    return ranges_m[i] >= range_min_m && ranges_m[i] < range_max_m;
  }
};

/// A robot pose reported by the platform's own odometry, in the `odom` frame (drifts).
struct OdometryPose {
  Time time;
  Pose2 odom_from_base;
};

/// Encoder tick increments since the previous WheelTicks record, per wheel, front to back on
/// each side. A two-wheel robot has one entry per side; the ECE276A robot has two (FR, RR / FL,
/// RL). Ticks per revolution and wheel radius are robot parameters, not part of the record.
struct WheelTicks {
  Time time;
  std::vector<std::int32_t> right_ticks;
  std::vector<std::int32_t> left_ticks;
};

/// One inertial sample in the IMU frame (aligned with base_link here): angular rate in rad/s and
/// specific force in m/s^2 (gravity included, as an accelerometer measures it).
struct ImuSample {
  Time time;
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration_m_s2 = Eigen::Vector3d::Zero();
};

/// A sensor record as the SLAM stack receives it, from a simulator or a real log alike. An
/// RgbdFrame is megabytes: records are moved along, never copied per consumer, and a consumer that
/// has no use for frames (the scan estimators, a CARMEN log) skips them and counts them.
using Record = std::variant<LaserScan, OdometryPose, WheelTicks, ImuSample, RgbdFrame>;

/// Time stamp of any record.
inline Time RecordTime(const Record& record) {
  return std::visit([](const auto& r) { return r.time; }, record);
}

/// A reference pose of base_link in the `map` frame: simulator truth, or a log's corrected pose.
/// It travels on its own channel beside the records and only evaluation reads it.
struct GroundTruthPose {
  Time time;
  Pose2 map_from_base;
};

}  // namespace slamrig
