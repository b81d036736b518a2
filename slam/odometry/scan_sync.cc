// Sensor synchronisation on lidar time stamps (Wang, "Simultaneous Localization and Mapping with
// Texture", ECE276A report, Sec. III-A): IMU samples within one lidar interval are averaged,
// encoder counts summed, and v, omega integrated with the differential-drive model (Eq. 6).
#include "slam/odometry/scan_sync.h"

#include <cmath>
#include <optional>

#include "slam/odometry/rot_trans_rot_model.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {}  // namespace

OdometrySource ResolveOdometrySource(const std::vector<Record>& records, OdometrySource wanted) {
  if (wanted != OdometrySource::kAuto) return wanted;
  bool poses = false;
  for (const Record& r : records) {
    if (std::holds_alternative<WheelTicks>(r)) return OdometrySource::kWheelTicks;
    poses = poses || std::holds_alternative<OdometryPose>(r);
  }
  return poses ? OdometrySource::kOdometryPoses : OdometrySource::kNone;
}

namespace {

// SE(2) translation Jacobian V(theta) applied to (x, y): the chord of a constant-twist motion.
Eigen::Vector2d ApplyV(double theta, const Eigen::Vector2d& v) {
  const double a = Sinc(theta);
  const double b = std::abs(theta) < 1e-4 ? 0.5 * theta : (1.0 - std::cos(theta)) / theta;
  return {a * v.x() - b * v.y(), b * v.x() + a * v.y()};
}

// Constant-twist (SE(2) exp/log) interpolation between two odometry poses: exact for motion at
// constant linear and angular velocity.
Pose2 Interpolate(const OdometryPose& a, const OdometryPose& b, Time t) {
  const double span = SecondsBetween(b.time, a.time);
  if (!(span > 0.0)) return b.odom_from_base;
  const double s = SecondsBetween(t, a.time) / span;
  const Pose2 delta = a.odom_from_base.Between(b.odom_from_base);
  const double theta = delta.theta();
  // log: V(theta)^-1 * translation.
  const double a11 = Sinc(theta);
  const double b11 = std::abs(theta) < 1e-4 ? 0.5 * theta : (1.0 - std::cos(theta)) / theta;
  const double det = a11 * a11 + b11 * b11;
  const Eigen::Vector2d rho((a11 * delta.x() + b11 * delta.y()) / det,
                            (-b11 * delta.x() + a11 * delta.y()) / det);
  const Eigen::Vector2d chord = ApplyV(s * theta, s * rho);
  return a.odom_from_base * Pose2(chord.x(), chord.y(), s * theta);
}

}  // namespace

std::vector<std::string> ScanSyncOptions::Validate() const {
  return PrefixErrors("sync", robot.Validate());
}

ScanSynchronizer::ScanSynchronizer(const ScanSyncOptions& options, OdometrySource source)
    : options_(options), source_(source) {
  SLAMRIG_CHECK_VALID(options_, "ScanSyncOptions");
  SLAMRIG_CHECK(source != OdometrySource::kAuto, "ScanSynchronizer needs a resolved source");
}

std::vector<SyncedScan> ScanSynchronizer::Add(const Record& record) {
  std::vector<SyncedScan> out;
  switch (source_) {
    case OdometrySource::kWheelTicks:
      if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
        interval_.AddTicks(*ticks);
        last_ticks_time_ = ticks->time;
        ticks_since_scan_ = true;
      } else if (const auto* imu = std::get_if<ImuSample>(&record)) {
        interval_.AddGyro(imu->angular_velocity_rad_s.z());
      } else if (const auto* scan = std::get_if<LaserScan>(&record)) {
        out.push_back(CompleteTicks(*scan));
      }
      break;
    case OdometrySource::kOdometryPoses:
      if (const auto* odom = std::get_if<OdometryPose>(&record)) {
        CompletePending(odom, &out);
        last_odometry_ = *odom;
      } else if (const auto* scan = std::get_if<LaserScan>(&record)) {
        pending_.push_back(*scan);
      }
      break;
    case OdometrySource::kAuto:
    case OdometrySource::kNone:
      if (const auto* scan = std::get_if<LaserScan>(&record)) {
        ++scans_without_odometry_;
        out.push_back(CompleteWithPose(*scan, Pose2()));
      }
      break;
  }
  return out;
}

std::vector<SyncedScan> ScanSynchronizer::Flush() {
  std::vector<SyncedScan> out;
  CompletePending(nullptr, &out);
  return out;
}

void ScanSynchronizer::SetSweepVelocity(SyncedScan* synced) const {
  if (!options_.deskew || !(synced->dt_s > 0.0) || synced->scan.time_increment_s == 0.0) return;
  // distance_m is unsigned from odometry poses: the increment says forwards or backwards.
  const double distance = std::copysign(synced->distance_m, synced->increment.x());
  synced->scan.sweep_velocity = {.forward_m_s = distance / synced->dt_s,
                                 .yaw_rate_rad_s = synced->yaw_change_rad / synced->dt_s};
}

// Encoder counts summed and gyro rates averaged over the interval since the previous scan.
SyncedScan ScanSynchronizer::CompleteTicks(const LaserScan& scan) {
  SyncedScan synced;
  synced.scan = scan;
  if (last_scan_time_) {
    const double dt = SecondsBetween(scan.time, *last_scan_time_);
    synced.imu_samples = interval_.gyro_samples();
    const OdometryInterval::Motion motion =
        interval_.Take(options_.robot, dt, options_.use_gyro, &held_rate_);
    gyro_fallbacks_ += motion.gyro_fallback;
    synced.dt_s = dt;
    synced.distance_m = motion.distance_m;
    synced.yaw_change_rad = motion.yaw_rad;
    synced.increment = DiffDriveIncrement(synced.distance_m, motion.yaw_rad, options_.integration);
    SetSweepVelocity(&synced);
    pose_ = pose_ * synced.increment;
    if (!interval_.has_ticks()) ++scans_without_odometry_;
    if (!ticks_since_scan_ && last_ticks_time_) {
      synced.odometry_gap_s = SecondsBetween(scan.time, *last_ticks_time_);
    }
  } else if (!interval_.has_ticks()) {
    ++scans_without_odometry_;
  }
  synced.odom_from_base = pose_;
  last_scan_time_ = scan.time;
  ticks_since_scan_ = false;
  // Counts before the first scan belong to no interval; start every interval empty.
  interval_.Clear();
  return synced;
}

SyncedScan ScanSynchronizer::CompleteWithPose(const LaserScan& scan, const Pose2& pose) {
  SyncedScan synced;
  synced.scan = scan;
  synced.odom_from_base = pose;
  if (last_scan_time_) synced.dt_s = SecondsBetween(scan.time, *last_scan_time_);
  if (previous_scan_pose_) {
    synced.increment = previous_scan_pose_->Between(pose);
    synced.distance_m = RotTransRot::FromIncrement(synced.increment).trans_m;
    synced.yaw_change_rad = synced.increment.theta();
    SetSweepVelocity(&synced);
  }
  previous_scan_pose_ = pose;
  last_scan_time_ = scan.time;
  return synced;
}

// Pending scans get the odometry pose at their time: interpolated between the last pose before
// and `next` after them, else the nearest one there is.
void ScanSynchronizer::CompletePending(const OdometryPose* next, std::vector<SyncedScan>* out) {
  for (const LaserScan& scan : pending_) {
    Pose2 pose;
    const OdometryPose* last = last_odometry_ ? &*last_odometry_ : nullptr;
    // No sample since the previous scan: the odometry is silent from `last` to `next` (or to
    // this scan when none came after it).
    const bool silent = last && last_scan_time_ && last->time <= *last_scan_time_;
    double gap_s = 0.0;
    if (last && next && last->time <= scan.time && scan.time <= next->time) {
      pose = Interpolate(*last, *next, scan.time);
      gap_s = SecondsBetween(next->time, last->time);
    } else if (last) {
      pose = last->odom_from_base;
      gap_s = SecondsBetween(scan.time, last->time);
    } else if (next) {
      pose = next->odom_from_base;
    } else {
      ++scans_without_odometry_;
    }
    out->push_back(CompleteWithPose(scan, pose));
    if (silent) out->back().odometry_gap_s = gap_s;
  }
  pending_.clear();
}

ScanSyncResult SyncToScans(const std::vector<Record>& records, const ScanSyncOptions& options) {
  SLAMRIG_CHECK_VALID(options, "ScanSyncOptions");
  ScanSyncResult result;
  result.source_used = ResolveOdometrySource(records, options.source);
  ScanSynchronizer sync(options, result.source_used == OdometrySource::kAuto ? OdometrySource::kNone
                                                                             : result.source_used);
  for (const Record& record : records) {
    for (SyncedScan& s : sync.Add(record)) result.scans.push_back(std::move(s));
  }
  for (SyncedScan& s : sync.Flush()) result.scans.push_back(std::move(s));
  result.gyro_fallbacks = sync.gyro_fallbacks();
  result.scans_without_odometry = sync.scans_without_odometry();
  return result;
}

std::vector<Pose2> DeadReckoningPoses(const std::vector<SyncedScan>& scans) {
  std::vector<Pose2> poses;
  poses.reserve(scans.size());
  Pose2 pose;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (i > 0) pose = pose * scans[i].increment;
    poses.push_back(pose);
  }
  return poses;
}

}  // namespace slamrig::slam
