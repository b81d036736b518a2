#pragma once

#include <optional>
#include <string>
#include <vector>

#include "slam/odometry/diff_drive_model.h"
#include "slam/odometry/odometry_interval.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// Where the motion between scans comes from.
enum class OdometrySource {
  kAuto,           ///< wheel ticks if the log has any, else odometry poses, else none
  kWheelTicks,     ///< encoder counts (+ gyro), the ECE276A robot and the simulator's encoders
  kOdometryPoses,  ///< the platform's own odometry poses (CARMEN ODOM)
  kNone,           ///< no odometry: every increment is the identity
};

/// How records are reduced to one motion input per laser scan.
struct ScanSyncOptions {
  OdometrySource source = OdometrySource::kAuto;
  DiffDriveParams robot;  ///< used for wheel ticks
  bool use_gyro = true;   ///< yaw from the IMU's mean z rate when it has samples in the interval
  DiffDriveIntegration integration = DiffDriveIntegration::kExactArc;
  /// Give each scan the velocity of the interval before it (LaserScan::sweep_velocity), so that
  /// a scan whose beams are taken over time (time_increment_s > 0) is undistorted by the motion
  /// during its sweep. A constant-velocity guess; no effect on scans with simultaneous beams.
  bool deskew = true;

  /// One message per broken rule (prefixed "sync.").
  std::vector<std::string> Validate() const;
};

/// The field table of ScanSyncOptions (slam/config/fields.h): a configuration's `odometry:` map.
/// The robot geometry is not a field: it comes from the robot file or the log.
template <typename V>
void VisitFields(V& v, ScanSyncOptions& o) {
  v.Enum("source", o.source,
         {{OdometrySource::kAuto, "auto"},
          {OdometrySource::kWheelTicks, "wheel_ticks"},
          {OdometrySource::kOdometryPoses, "poses"},
          {OdometrySource::kNone, "none"}});
  v("use_gyro", o.use_gyro);
  v("deskew", o.deskew);
  v.Enum("integration", o.integration,
         {{DiffDriveIntegration::kExactArc, "exact_arc"}, {DiffDriveIntegration::kEuler, "euler"}});
}

/// One laser scan with the odometry synchronised to its time stamp.
struct SyncedScan {
  LaserScan scan;
  /// Odometry pose at the scan time (odom frame; identity at the first scan for wheel ticks).
  Pose2 odom_from_base;
  /// Motion since the previous scan in the robot frame: previous.Between(this); identity first.
  Pose2 increment;
  double dt_s = 0.0;            ///< time since the previous scan (0 for the first)
  double distance_m = 0.0;      ///< travelled distance in the interval (v * tau), signed
  double yaw_change_rad = 0.0;  ///< heading change in the interval (omega * tau)
  int imu_samples = 0;          ///< gyro samples averaged for this interval
  /// How long the odometry said nothing about this scan's motion: with odometry poses, the time
  /// between the two samples the scan's pose was interpolated between (or held from) when that
  /// span holds no sample after the previous scan; with wheel ticks, the time since the last
  /// tick record when the interval had none. 0 otherwise, and without odometry. A long one is a
  /// gap in the log (the robot may have turned through it while the increment holds still).
  double odometry_gap_s = 0.0;
};

/// The synchronised scans and what went wrong on the way (counted, never silent).
struct ScanSyncResult {
  std::vector<SyncedScan> scans;
  OdometrySource source_used = OdometrySource::kNone;
  int gyro_fallbacks = 0;  ///< intervals with no IMU sample although use_gyro: yaw held/encoders
  int scans_without_odometry = 0;  ///< scans before any odometry was seen (identity motion)
};

/// The incremental form of SyncToScans, for records that arrive one at a time (a simulator
/// stepping on the same clock as SLAM). Feeding a record list through Add() then Flush() gives
/// exactly SyncToScans' scans.
class ScanSynchronizer {
 public:
  /// `source` must be resolved: kWheelTicks, kOdometryPoses or kNone (checked).
  ScanSynchronizer(const ScanSyncOptions& options, OdometrySource source);

  /// Takes the next record and returns the scans it completes: with wheel ticks a scan is
  /// complete when it arrives; with odometry poses when the next pose after it arrives.
  std::vector<SyncedScan> Add(const Record& record);
  /// Completes the scans still waiting for odometry (end of the data).
  std::vector<SyncedScan> Flush();

  OdometrySource source() const { return source_; }
  int gyro_fallbacks() const { return gyro_fallbacks_; }
  int scans_without_odometry() const { return scans_without_odometry_; }

 private:
  SyncedScan CompleteTicks(const LaserScan& scan);
  SyncedScan CompleteWithPose(const LaserScan& scan, const Pose2& pose);
  /// The interval's velocity into synced->scan.sweep_velocity (options_.deskew).
  void SetSweepVelocity(SyncedScan* synced) const;
  void CompletePending(const OdometryPose* next, std::vector<SyncedScan>* out);

  ScanSyncOptions options_;
  OdometrySource source_;
  int gyro_fallbacks_ = 0;
  int scans_without_odometry_ = 0;
  std::optional<Time> last_scan_time_;
  // Wheel ticks: sums since the previous scan, and when the last tick record came.
  std::optional<Time> last_ticks_time_;
  bool ticks_since_scan_ = false;
  OdometryInterval interval_;
  std::optional<double> held_rate_;  // last interval's mean gyro rate, for dropouts
  Pose2 pose_;
  // Odometry poses: the last one seen, and scans waiting for the next one.
  std::optional<OdometryPose> last_odometry_;
  std::optional<Pose2> previous_scan_pose_;
  std::vector<LaserScan> pending_;
};

/// Reduces time-ordered records to one input per scan, with the scan times as the reference
/// (Wang, ECE276A report, Sec. III-A): encoder counts between two scans are summed, the gyro z
/// samples between them averaged (omega * tau is the yaw change), and the step integrated with the
/// differential-drive model; odometry poses are interpolated to the scan time. Records are taken
/// in vector order, so a log with a few out-of-order stamps still pairs each scan with the
/// records written around it.
ScanSyncResult SyncToScans(const std::vector<Record>& records, const ScanSyncOptions& options);

/// The source `wanted` means for `records`: kAuto becomes wheel ticks if there are any, else
/// odometry poses if there are any, else kNone; any other value is returned as it is.
OdometrySource ResolveOdometrySource(const std::vector<Record>& records, OdometrySource wanted);

/// The dead-reckoning trajectory implied by `scans`: poses relative to the first scan.
std::vector<Pose2> DeadReckoningPoses(const std::vector<SyncedScan>& scans);

}  // namespace slamrig::slam
