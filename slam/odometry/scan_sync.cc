// Sensor synchronisation on lidar time stamps (Wang, "Simultaneous Localization and Mapping with
// Texture", ECE276A report, Sec. III-A): IMU samples within one lidar interval are averaged, encoder
// counts summed, and v, omega integrated with the differential-drive model (Eq. 6).
#include "slam/odometry/scan_sync.h"

#include <cmath>
#include <optional>

#include "slam/odometry/rot_trans_rot_model.h"
#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

double SideMean(const std::vector<std::int32_t>& ticks) {
  if (ticks.empty()) return 0.0;
  double sum = 0.0;
  for (const std::int32_t t : ticks) sum += t;
  return sum / static_cast<double>(ticks.size());
}

OdometrySource Resolve(const std::vector<Record>& records, OdometrySource wanted) {
  if (wanted != OdometrySource::kAuto) return wanted;
  bool poses = false;
  for (const Record& r : records) {
    if (std::holds_alternative<WheelTicks>(r)) return OdometrySource::kWheelTicks;
    poses = poses || std::holds_alternative<OdometryPose>(r);
  }
  return poses ? OdometrySource::kOdometryPoses : OdometrySource::kNone;
}

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

// Odometry poses at each scan for a log that reports poses.
void SyncPoses(const std::vector<Record>& records, ScanSyncResult& result) {
  // For every record index, the index of the next OdometryPose at or after it (lookahead).
  std::vector<std::size_t> next_odom(records.size() + 1, records.size());
  for (std::size_t i = records.size(); i-- > 0;) {
    next_odom[i] = std::holds_alternative<OdometryPose>(records[i]) ? i : next_odom[i + 1];
  }
  std::optional<OdometryPose> last;
  std::optional<Pose2> previous_scan_pose;
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (const auto* odom = std::get_if<OdometryPose>(&records[i])) {
      last = *odom;
      continue;
    }
    const auto* scan = std::get_if<LaserScan>(&records[i]);
    if (scan == nullptr) continue;
    const std::size_t n = next_odom[i];
    const OdometryPose* next = n < records.size() ? &std::get<OdometryPose>(records[n]) : nullptr;
    Pose2 pose;
    if (last && next && last->time <= scan->time && scan->time <= next->time) {
      pose = Interpolate(*last, *next, scan->time);
    } else if (last) {
      pose = last->odom_from_base;
    } else if (next) {
      pose = next->odom_from_base;
    } else {
      ++result.scans_without_odometry;
    }
    SyncedScan synced;
    synced.scan = *scan;
    synced.odom_from_base = pose;
    if (previous_scan_pose) {
      synced.increment = previous_scan_pose->Between(pose);
      synced.dt_s = SecondsBetween(scan->time, result.scans.back().scan.time);
      synced.distance_m = RotTransRot::FromIncrement(synced.increment).trans_m;
      synced.yaw_change_rad = synced.increment.theta();
    }
    previous_scan_pose = pose;
    result.scans.push_back(std::move(synced));
  }
}

// Encoder counts summed and gyro rates averaged per scan interval.
void SyncTicks(const std::vector<Record>& records, const ScanSyncOptions& options,
               ScanSyncResult& result) {
  const double metres_per_tick = options.robot.MetresPerTick();
  double right_ticks = 0.0, left_ticks = 0.0, gyro_sum = 0.0;
  int gyro_count = 0;
  bool seen_ticks = false;
  std::optional<double> held_rate;  // last interval's mean gyro rate, for dropouts
  Pose2 pose;
  for (const Record& record : records) {
    if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
      right_ticks += SideMean(ticks->right_ticks);
      left_ticks += SideMean(ticks->left_ticks);
      seen_ticks = true;
      continue;
    }
    if (const auto* imu = std::get_if<ImuSample>(&record)) {
      gyro_sum += imu->angular_velocity_rad_s.z();
      ++gyro_count;
      continue;
    }
    const auto* scan = std::get_if<LaserScan>(&record);
    if (scan == nullptr) continue;
    SyncedScan synced;
    synced.scan = *scan;
    if (!result.scans.empty()) {
      const double dt = SecondsBetween(scan->time, result.scans.back().scan.time);
      const double right_m = right_ticks * metres_per_tick;
      const double left_m = left_ticks * metres_per_tick;
      double yaw = (right_m - left_m) / options.robot.track_width_m;
      if (options.use_gyro) {
        if (gyro_count > 0) {
          held_rate = gyro_sum / gyro_count;
          yaw = *held_rate * dt;
        } else {
          ++result.gyro_fallbacks;
          if (held_rate) yaw = *held_rate * dt;
        }
      }
      synced.dt_s = dt;
      synced.distance_m = 0.5 * (right_m + left_m);
      synced.yaw_change_rad = yaw;
      synced.imu_samples = gyro_count;
      synced.increment = DiffDriveIncrement(synced.distance_m, yaw, options.integration);
      pose = pose * synced.increment;
      if (!seen_ticks) ++result.scans_without_odometry;
    } else if (!seen_ticks) {
      ++result.scans_without_odometry;
    }
    synced.odom_from_base = pose;
    // Counts before the first scan belong to no interval; start every interval empty.
    right_ticks = left_ticks = gyro_sum = 0.0;
    gyro_count = 0;
    result.scans.push_back(std::move(synced));
  }
}

}  // namespace

std::vector<std::string> ScanSyncOptions::Validate() const {
  std::vector<std::string> errors;
  for (const std::string& e : robot.Validate()) errors.push_back("sync." + e);
  return errors;
}

ScanSyncResult SyncToScans(const std::vector<Record>& records, const ScanSyncOptions& options) {
  SLAMRIG_CHECK(options.Validate().empty(), "invalid ScanSyncOptions");
  ScanSyncResult result;
  result.source_used = Resolve(records, options.source);
  switch (result.source_used) {
    case OdometrySource::kWheelTicks:
      SyncTicks(records, options, result);
      break;
    case OdometrySource::kOdometryPoses:
      SyncPoses(records, result);
      break;
    case OdometrySource::kAuto:
    case OdometrySource::kNone:
      for (const Record& record : records) {
        if (const auto* scan = std::get_if<LaserScan>(&record)) {
          SyncedScan synced;
          synced.scan = *scan;
          if (!result.scans.empty()) {
            synced.dt_s = SecondsBetween(scan->time, result.scans.back().scan.time);
          }
          result.scans.push_back(std::move(synced));
        }
      }
      result.scans_without_odometry = static_cast<int>(result.scans.size());
      break;
  }
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
