#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "slam/io/carmen_reader.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// A log as the SLAM stack sees it: sensor records in time order, plus the reference poses on
/// their own channel, which only evaluation may read.
struct Dataset {
  std::vector<Record> records;
  std::vector<GroundTruthPose> reference;
  std::string source;              ///< file it came from
  std::string format;              ///< its format ("carmen", "ece276a"; see log_reader.h)
  std::string reference_kind;      ///< what `reference` is, e.g. "GMapping-corrected poses"
  std::vector<std::string> notes;  ///< quirks found while reading, for the user
  /// One line when the log was cut short (a recording killed mid-way) and read up to the cut:
  /// the file, where it stopped and what was recovered ("run.mcap truncated at byte 3,000,000:
  /// recovered 2,411 scans of an unknown total; the rest is lost"); also among `notes`. Empty
  /// for a whole log.
  std::string truncated;
  /// The log's stamps were unusable and its times were made up from line order: the data's
  /// duration is not a duration, and no real-time factor can be given.
  bool times_synthesised = false;
};

/// `n` with a comma between groups of three digits ("2,411"), as notes print counts. Inline: the
/// bag readers (slamrig_bag) use it without linking slamrig_io.
inline std::string GroupedCount(std::uint64_t n) {
  std::string digits = std::to_string(n);
  for (std::size_t i = digits.size(); i > 3; i -= 3) digits.insert(i - 3, 1, ',');
  return digits;
}

/// Turns a CARMEN log into a Dataset.
/// - GMapping-corrected logs: the scans' poses become the reference; the raw odometry is
///   recovered from the ODOM lines as u_k = inverse(P_{k-1}) * O_k (SOURCE.md of
///   carmen_corrected) and chained from the first scan's pose, so dead reckoning and SLAM see
///   the robot's real odometry. ODOM lines before the first scan are dropped (counted in notes).
/// - Other logs: ODOM lines and the odometry pose stored with each laser line are the odometry;
///   TRUEPOS lines, if any, are the reference.
Dataset CarmenToDataset(const CarmenLog& log);

}  // namespace slamrig::slam
