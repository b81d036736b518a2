#pragma once

#include <string>

#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// The trajectory as TUM text (`t x y z qx qy qz qw` per line, seconds and metres; z = 0 and a
/// yaw-only quaternion), the format evo and the TUM RGB-D tools read.
std::string FormatTum(const Trajectory& trajectory);

/// Writes FormatTum(trajectory) to `path` atomically.
void WriteTum(const std::string& path, const Trajectory& trajectory);

/// Reads a TUM trajectory. Comment lines (#) and blank lines are skipped. The yaw is taken from
/// the quaternion; a non-unit quaternion, a pose tilted out of the plane, a wrong field count or
/// (with `in_time_order`) time going backwards is a ParseError naming the file, line and field.
/// Without `in_time_order` the poses are kept in file order whatever their stamps (a program's
/// poses at a log's scans, whose stamps may go backwards).
Trajectory ReadTum(const std::string& path, bool in_time_order = true);

}  // namespace slamrig::slam
