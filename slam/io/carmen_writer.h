#pragma once

#include <string>

#include "slam/types/records.h"

namespace slamrig::slam {

/// Writes a CARMEN log that ReadCarmenLog and other CARMEN tools read: PARAM, ODOM, ROBOTLASER1
/// and TRUEPOS lines, in the order they are written, every number in its shortest exact form (so
/// a log read back gives bit-identical records), buffered in large blocks. Nothing appears at
/// `path` until Commit() renames the temporary file into place; destroying an uncommitted writer
/// removes it.
class CarmenWriter {
 public:
  explicit CarmenWriter(std::string path);
  ~CarmenWriter();
  CarmenWriter(const CarmenWriter&) = delete;
  CarmenWriter& operator=(const CarmenWriter&) = delete;

  /// `PARAM key value`.
  void WriteParam(const std::string& key, const std::string& value);
  /// `ODOM x y theta tv rv accel` with velocities in m/s and rad/s.
  void WriteOdometry(const OdometryPose& odom, double tv_m_s, double rv_rad_s);
  /// `ROBOTLASER1`: the scan with the laser pose and the robot's odometry pose at scan time.
  void WriteLaser(const LaserScan& scan, const Pose2& odom_from_base_at_scan);
  /// `TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta`.
  void WriteTruePos(const GroundTruthPose& truth, const Pose2& odom_from_base);
  /// Flushes and renames the file into place.
  void Commit();

 private:
  void EndLine();
  void Flush();
  void Stamp(Time time);

  std::string path_;
  std::string tmp_path_;
  std::string buffer_;    // lines not yet written
  void* file_ = nullptr;  // FILE*
};

}  // namespace slamrig::slam
