#pragma once

#include <map>
#include <string>
#include <vector>

#include "slam/types/records.h"

namespace slamrig::slam {

/// How to read a CARMEN log.
struct CarmenReadOptions {
  /// Turn malformed lines of known message types into counted skips instead of errors.
  bool lenient = false;
  /// Readings at or above this are "no return" codes whatever the log claims (SICK: 81.83 m).
  double no_return_range_m = 80.0;
  /// A log cut short (a last line without its end of line that does not parse as a whole
  /// message, a gzip stream that ends early) is an error, instead of read up to its last whole
  /// line with CarmenLog::truncated saying so.
  bool strict = false;
};

/// A laser message of the log with the poses logged beside it.
struct CarmenScan {
  LaserScan scan;
  /// The pose field of the line (FLASER x y theta, ROBOTLASER1 robot pose): the odometry pose at
  /// scan time in a raw log, the corrected pose in a GMapping-corrected log.
  Pose2 logged_pose;
  /// The odometry pose field (FLASER odom_x odom_y odom_theta; ROBOTLASER1: same as logged_pose).
  Pose2 odom_pose;
  /// False for RAWLASER messages, which carry no pose.
  bool has_pose = true;
  int line = 0;  ///< 1-based line number in the file
};

/// One ODOM message.
struct CarmenOdometry {
  OdometryPose odometry;
  int line = 0;
};

/// What was read and what was left out, with reasons; printed by the tools.
struct CarmenStats {
  std::map<std::string, int> messages;          ///< message type -> count accepted
  std::map<std::string, int> unknown_messages;  ///< unknown type -> count (not fatal)
  std::map<std::string, int> skipped;           ///< reason -> lines skipped
  int out_of_order_times = 0;                   ///< stamps earlier than the previous record's
};

/// A whole CARMEN log, in file order. All messages are kept in file order and their times made
/// non-decreasing: CARMEN loggers write in arrival order, and the Radish logs have out-of-order,
/// zero and garbage stamps (see shared/datasets/carmen_corrected/SOURCE.md).
struct CarmenLog {
  std::string path;
  std::vector<CarmenScan> scans;              ///< FLASER, RLASER, ROBOTLASER1, RAWLASER1-4
  std::vector<CarmenOdometry> odometry;       ///< ODOM lines, GMapping echo lines excluded
  std::vector<GroundTruthPose> true_poses;    ///< TRUEPOS lines
  std::map<std::string, std::string> params;  ///< PARAM name -> value
  /// The log is a GMapping "corrected" log: its FLASER poses are a reference, its ODOM lines
  /// are corrected-pose-plus-raw-increment (detected from the echo ODOM line after each scan: its
  /// corrected pose again).
  bool is_corrected = false;
  /// False when the stamps are all zero, constant or garbage: times were then synthesized from
  /// file order (one millisecond per line) and `notes` says so.
  bool timestamps_usable = true;
  CarmenStats stats;
  std::vector<std::string> notes;  ///< human-readable remarks about quirks found
  /// Where a log cut short stopped and how many scans were recovered (also among `notes`); empty
  /// for a whole log.
  std::string truncated;
};

/// Reads a plain or gzip CARMEN log. Throws ParseError("file:line: field: problem") on a missing,
/// empty, binary or malformed file (malformed lines become counted skips with `lenient`).
/// A log cut short (see CarmenReadOptions::strict) is read up to its last whole line: a last
/// line without an end of line is kept when it parses as a whole known message (a log that
/// merely lacks its final newline), else dropped, as is an unfinished line of a gzip stream
/// that ends early; CarmenLog::truncated then says where it stopped.
///
/// Beam geometry of FLASER/RLASER, which carry no angles: a 180 degree field of view starting at
/// -90 degrees (CARMEN's documented default, "assume 1 degree resolution"); n beams are spaced by
/// pi / n for even n (180, 360: -90 deg .. +89 deg, as GMapping's RangeSensor lays them out and
/// as the corrected logs' poses were estimated with) and by pi / (n - 1) for odd n (181, 361:
/// -90 .. +90 deg). A `laser_front_laser_resolution` PARAM (degrees) overrides the spacing.
/// PARAMs `laser_time_increment_s` and `laser_range_min_m` (written by slamrig's simulator)
/// set the per-beam time step and minimum range of every scan.
CarmenLog ReadCarmenLog(const std::string& path, const CarmenReadOptions& options = {});

}  // namespace slamrig::slam
