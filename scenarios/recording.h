#pragma once

#include <string>
#include <utility>
#include <vector>

#include "sim/simulator.h"
#include "slam/io/bag/bag_writer.h"
#include "slam/types/pose2.h"

namespace slamrig::scenario {

/// How long a written run lasts.
struct RunOptions {
  /// Simulated seconds; 0 runs until the world's driver finishes (which an idle drive never does).
  double duration_s = 0.0;
  /// Safety stop for duration_s = 0, seconds.
  double max_duration_s = 7200.0;

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// The file format a recorded run is written in.
enum class RecordingFormat {
  kCarmen,   ///< run.log, a CARMEN log (slam::CarmenSink)
  kMcap,     ///< run/, a ROS 2 bag with MCAP storage (slam::BagSink)
  kSqlite3,  ///< run/, a ROS 2 bag with sqlite3 storage (slam::BagSink)
  kEce276a,  ///< Encoders<N>.npz, Imu<N>.npz, Hokuyo<N>.npz, Kinect<N>.npz, dataRGBD/ (ECE276A)
};

/// How a recorded run is written.
struct RecordingOptions {
  RecordingFormat format = RecordingFormat::kCarmen;
  /// Bags only: MCAP chunk compression (sqlite3 bags are never compressed).
  slam::McapCompression compression = slam::McapCompression::kZstd;
  /// Bags only: topic names (the ROS defaults).
  slam::BagTopicNames topics;
  /// ECE276A only: the dataset number <N> in the file names.
  int ece276a_dataset = 20;

  /// One RuleViolation() message per broken rule; empty when valid.
  std::vector<std::string> Validate() const;
};

/// What a written run contains.
struct RunSummary {
  double duration_s = 0.0;      ///< simulated seconds
  bool drive_finished = false;  ///< the world's driver completed its path or schedule
  int num_scans = 0;            ///< scans written (ROBOTLASER1 lines, /scan messages)
  int num_odometry = 0;         ///< odometry poses written (ODOM lines, /odom messages)
  int num_imu = 0;              ///< IMU samples fed to the odometry
  int num_frames = 0;           ///< RGB-D frames rendered (a robot with a camera)
  int frames_skipped = 0;       ///< of them, not written (a CARMEN log has no image line)
  Pose2 final_truth;            ///< map_from_base at the end
  Pose2 final_odometry;  ///< odom_from_base at the end (the robot's own encoder + gyro estimate)
  double path_length_m = 0.0;      ///< true distance driven
  std::vector<std::string> files;  ///< paths written
};

/// The PARAM lines of a CARMEN log of a simulated run: the lidar's range and mounting, what
/// slamrig's reader needs beyond ROBOTLASER1 (time increment, minimum range), world, robot, seed.
std::vector<std::pair<std::string, std::string>> CarmenLogParams(
    const sim::SimulatorOptions& options);

/// Runs a simulation and records it into `out_dir` (created if missing), every file atomically.
/// The simulator only emits records and the truth; what is written is the sinks' business:
///  - with RecordingFormat::kCarmen, run.log: a CARMEN log through slam::CarmenSink (PARAM,
///    ODOM, ROBOTLASER1, TRUEPOS). ODOM is the robot's own odometry, computed there from the
///    encoder ticks and gyro with the nominal radius and track; each scan carries the odometry
///    pose interpolated to its time, and a TRUEPOS line follows it with the ground truth;
///  - with kMcap or kSqlite3, run/: a ROS 2 bag through slam::BagSink (the records, the same
///    robot odometry on /odom and /tf, the truth at every scan on /ground_truth/odom); a bag
///    folder left by an earlier run is replaced;
///  - with kEce276a, the files of the UCSD ECE276A project 2 data through slam::Ece276aSink
///    (encoder ticks, IMU, Hokuyo scans, Kinect images), which the reports' own code and
///    slam::ReadEce276a read; the layout has no odometry or truth (truth.tum has it);
///  - a robot with a camera (robot.camera) renders frames into the stream (sim::CameraRig); a
///    bag carries them as sensor_msgs/Image and CameraInfo, the ECE276A layout as its RGB and
///    disparity PNGs, a CARMEN log skips and counts them;
///  - in every format, truth.tum: ground truth at every scan time (TUM format); world.yaml,
///    robot.yaml: the resolved world and robot; sim.yaml: seed, rates, duration, written last
///    (an earlier one removed first), so that a folder with a sim.yaml is complete.
/// Equal options give byte-identical files. Throws ConfigError for invalid `recording`
/// options, OutputError naming the file that cannot be written, Interrupted after
/// SIGINT/SIGTERM (the log's temporary file is removed).
RunSummary RecordSimulation(const sim::SimulatorOptions& options, const RunOptions& run,
                            const std::string& out_dir, const RecordingOptions& recording = {});

}  // namespace slamrig::scenario
