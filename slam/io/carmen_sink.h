#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/io/carmen_writer.h"
#include "slam/io/record_sink.h"
#include "slam/odometry/robot_odometry.h"

namespace slamrig::slam {

/// What a CARMEN log written from records carries besides them.
struct CarmenSinkOptions {
  /// The robot's own odometry for the ODOM lines: encoder ticks (and the gyro, when
  /// `odometry.use_gyro` and the records have IMU samples) integrated with the nominal geometry,
  /// as the robot itself would log it.
  WheelOdometryOptions odometry;
  /// PARAM lines at the top, in order.
  std::vector<std::pair<std::string, std::string>> params;
};

/// A RecordSink that writes a CARMEN log: ODOM for each WheelTicks record (the robot's own
/// encoder + gyro odometry), ROBOTLASER1 for each scan (with the odometry pose interpolated to
/// its time, so it waits for the next ODOM) and, when the scan came with the truth, a TRUEPOS
/// line after it. ImuSamples feed the odometry; OdometryPose records (a log replayed) are
/// written as ODOM lines instead when there are no ticks. CARMEN has no image line: RgbdFrame
/// records are skipped and counted (frames_skipped()).
class CarmenSink final : public RecordSink {
 public:
  CarmenSink(const std::string& path, const CarmenSinkOptions& options);

  void Add(const Record& record, const GroundTruthPose* truth) override;
  void Commit() override;

  int scans() const { return scans_; }
  int odometry_lines() const { return odometry_lines_; }
  /// RgbdFrame records left out (CARMEN cannot carry them).
  int frames_skipped() const { return frames_skipped_; }
  int imu_samples() const { return odometry_.imu_samples(); }
  /// The robot's odometry pose after the last WheelTicks record.
  const Pose2& odometry_pose() const { return odometry_.pose(); }

 private:
  void WriteOdometry(const OdometryPose& pose);
  void WriteHeldScans(const std::optional<OdometryPose>& next);

  CarmenWriter writer_;
  RobotOdometry odometry_;
  std::optional<OdometryPose> last_odometry_;
  std::vector<std::pair<LaserScan, std::optional<GroundTruthPose>>> held_;
  int scans_ = 0;
  int odometry_lines_ = 0;
  int frames_skipped_ = 0;
};

}  // namespace slamrig::slam
