#pragma once

#include <string>
#include <vector>

#include "slam/io/bag/bag_writer.h"
#include "slam/io/dataset.h"

namespace slamrig::slam {

/// Options of ReadBag.
struct BagReaderOptions {
  /// Topics to read; the defaults are the ones BagWriter writes.
  BagTopicNames topics;
  /// Encoder ticks per wheel revolution, to turn JointState positions back into ticks; 0 takes
  /// the value the bag records (kTicksKey, written by BagWriter), else 360 (the ECE276A robot).
  double ticks_per_revolution = 0.0;
  /// The robot's frame: /tf_static transforms from it give each scan's base_from_laser.
  std::string base_frame = "base_link";

  /// One RuleViolation() message per broken rule; empty when valid.
  std::vector<std::string> Validate() const;
};

/// Reads a ROS 2 bag into a Dataset: a bag folder (storage and files from metadata.yaml, or the
/// one .mcap/.db3 file inside when it has none) or a single .mcap or .db3 file, told apart by
/// its magic bytes. Messages are taken in (header stamp, storage) order:
///   /scan LaserScan -> LaserScan, base_from_laser from the latest /tf_static transform
///     base_frame -> the scan's frame_id (identity, and a note, if there is none);
///   /imu Imu -> ImuSample; /odom Odometry -> OdometryPose;
///   /joint_states JointState -> WheelTicks: ticks = round(position * ticks_per_revolution /
///     2 pi) per wheel, minus the previous message's, starting from 0 (exact for bags BagWriter
///     wrote); the side of each joint comes from its name (WheelJointIsRight, or a name with
///     "right"/"left" in it);
///   /ground_truth/odom Odometry -> Dataset::reference.
/// /tf, /clock and any other topic are skipped and listed in the notes with their counts.
/// Throws ParseError naming the file (and the topic and message index for a message that does
/// not decode) for a truncated file, bad magic, a CRC mismatch, a chunk that does not
/// decompress, a message too short or with a bad length, or a read topic of the wrong type.
Dataset ReadBag(const std::string& path, const BagReaderOptions& options = {});

/// True if `path` is a bag ReadBag would try to read: a folder with a metadata.yaml or with
/// .mcap/.db3 files, or a file that starts with the MCAP or sqlite3 magic.
bool LooksLikeBag(const std::string& path);

}  // namespace slamrig::slam
