#pragma once

#include <string>

#include "slam/io/bag/bag_writer.h"
#include "slam/io/record_sink.h"
#include "slam/odometry/robot_odometry.h"

namespace slamrig::slam {

/// What a ROS 2 bag written from records carries besides them.
struct BagSinkOptions {
  /// Storage, compression, topic and frame names, ticks per revolution (BagWriter).
  BagWriterOptions writer;
  /// The robot's own odometry for /odom and /tf: encoder ticks (and the gyro, when
  /// `odometry.use_gyro`) integrated with the nominal geometry, exactly as CarmenSink's ODOM
  /// lines (both use RobotOdometry).
  WheelOdometryOptions odometry;

  /// One RuleViolation() message per broken rule; empty when valid.
  std::vector<std::string> Validate() const;
};

/// A RecordSink that writes a ROS 2 bag folder through BagWriter: every record on its topic
/// (/scan with /tf_static, /imu, /joint_states, an RgbdFrame as two sensor_msgs/Image and a
/// CameraInfo), after each WheelTicks record the robot's own
/// odometry pose at its time on /odom and /tf, OdometryPose records (a log replayed) as they
/// are, and the truth given with a record on /ground_truth/odom right after it. Nothing appears
/// at the folder until Commit().
class BagSink final : public RecordSink {
 public:
  /// Throws ConfigError for invalid options, std::runtime_error if `folder` exists or cannot
  /// be written (see BagWriter).
  BagSink(const std::string& folder, const BagSinkOptions& options);
  /// The same messages as an MCAP stream through `output` (BagWriter's stream form).
  BagSink(McapWriter::Output output, const BagSinkOptions& options);

  void Add(const Record& record, const GroundTruthPose* truth) override;
  void Commit() override;
  /// The writer, for what a stream adds (metadata records).
  BagWriter& writer() { return writer_; }

  int scans() const { return scans_; }
  /// RGB-D frames written (each an rgb and a depth image and a camera info).
  int frames() const { return frames_; }
  int odometry_messages() const { return odometry_.poses(); }
  int imu_samples() const { return odometry_.imu_samples(); }
  /// The robot's odometry pose after the last WheelTicks record.
  const Pose2& odometry_pose() const { return odometry_.pose(); }

 private:
  BagWriter writer_;
  RobotOdometry odometry_;
  int scans_ = 0;
  int frames_ = 0;
};

}  // namespace slamrig::slam
