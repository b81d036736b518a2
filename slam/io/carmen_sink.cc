#include "slam/io/carmen_sink.h"

#include <cmath>

#include "slam/types/trajectory.h"

namespace slamrig::slam {

CarmenSink::CarmenSink(const std::string& path, const CarmenSinkOptions& options)
    : writer_(path), odometry_(options.odometry) {
  for (const auto& [key, value] : options.params) writer_.WriteParam(key, value);
}

void CarmenSink::Add(const Record& record, const GroundTruthPose* truth) {
  if (const std::optional<OdometryPose> pose = odometry_.Add(record)) {
    WriteOdometry(*pose);
  } else if (const auto* scan = std::get_if<LaserScan>(&record)) {
    held_.emplace_back(*scan, truth ? std::optional<GroundTruthPose>(*truth) : std::nullopt);
    ++scans_;
  } else if (std::holds_alternative<RgbdFrame>(record)) {
    ++frames_skipped_;
  }
}

void CarmenSink::WriteOdometry(const OdometryPose& pose) {
  WriteHeldScans(pose);
  double tv = 0.0, rv = 0.0;
  if (last_odometry_ && pose.time > last_odometry_->time) {
    const double dt = SecondsBetween(pose.time, last_odometry_->time);
    const Pose2 delta = last_odometry_->odom_from_base.Between(pose.odom_from_base);
    tv = std::copysign(delta.translation().norm(), delta.x()) / dt;
    rv = delta.theta() / dt;
  }
  writer_.WriteOdometry(pose, tv, rv);
  last_odometry_ = pose;
  ++odometry_lines_;
}

// Held scans get the odometry pose at their time: interpolated between the last pose before
// and `next` after them, else the one there is.
void CarmenSink::WriteHeldScans(const std::optional<OdometryPose>& next) {
  for (const auto& [scan, truth] : held_) {
    Pose2 odom_at_scan;
    if (last_odometry_ && next) {
      odom_at_scan = next->time <= last_odometry_->time
                         ? next->odom_from_base
                         : InterpolatePoses(last_odometry_->odom_from_base, next->odom_from_base,
                                            SecondsBetween(scan.time, last_odometry_->time) /
                                                SecondsBetween(next->time, last_odometry_->time));
    } else if (last_odometry_ || next) {
      odom_at_scan = (last_odometry_ ? *last_odometry_ : *next).odom_from_base;
    }
    writer_.WriteLaser(scan, odom_at_scan);
    if (truth) writer_.WriteTruePos(*truth, odom_at_scan);
  }
  held_.clear();
}

void CarmenSink::Commit() {
  WriteHeldScans(std::nullopt);
  writer_.Commit();
}

}  // namespace slamrig::slam
