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
  /// A file cut short (a recording killed mid-way: no MCAP footer, a sqlite3 file shorter than
  /// its header says or whose rows stop being readable) is an error, instead of read up to the
  /// cut with Dataset::truncated saying so.
  bool strict = false;

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
/// not decode) for bad magic, a CRC mismatch, a chunk that does not decompress, a message too
/// short or with a bad length, or a read topic of the wrong type; for a truncated file only when
/// `strict` or when nothing before the cut can be read, or when it is not the bag's last file
/// (else the messages before the cut are read, and Dataset::truncated and a note say where it
/// stopped and how many scans it recovered).
/// Also a ParseError, listing every topic with its type and count and the `--topic KEY=NAME`
/// flags that would map them, when the scans are on another topic than options.topics.scan or
/// when none of the read topics has a message but other topics of their types do; another topic
/// of a read type (odometry, wheel joints, IMU) beside an empty read topic gets a note with the
/// flag.
Dataset ReadBag(const std::string& path, const BagReaderOptions& options = {});

/// True if `path` is a bag ReadBag would try to read: a folder with a metadata.yaml or with
/// .mcap/.db3 files, or a file that starts with the MCAP or sqlite3 magic.
bool LooksLikeBag(const std::string& path);

}  // namespace slamrig::slam
