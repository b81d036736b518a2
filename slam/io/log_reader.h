#pragma once

#include <string>

#include "slam/io/bag/bag_writer.h"
#include "slam/io/dataset.h"

namespace slamrig::slam {

/// The log formats slamrig reads.
enum class LogFormat {
  kCarmen,   ///< CARMEN text log, plain or .gz (real, corrected Radish, or `slamrig simulate`'s)
  kEce276a,  ///< an ECE276A robot dataset (folder + number, or one of its npz/csv files)
  kRos2Bag,  ///< a ROS 2 bag, MCAP or sqlite3 (its folder with metadata.yaml, or the file)
};

/// The name of `format` ("carmen", "ece276a", "ros2bag").
const char* LogFormatName(LogFormat format);

/// How logs are read.
struct LogReadOptions {
  bool lenient = false;  ///< CARMEN: count malformed lines instead of failing
  /// ROS 2 bags: the topics to read (the ROS defaults BagWriter writes).
  BagTopicNames topics;
};

/// The datasets folder: $SLAMRIG_DATA_DIR, else ../shared/datasets of the current folder when it
/// exists, else ../shared/datasets beside the source tree slamrig was built from.
std::string DataDir();

/// `path` itself when it exists (or names an ECE276A dataset), else `path` inside DataDir() when
/// that exists (`carmen_corrected/intel-corrected.log.gz`), else `path` unchanged (the reader then
/// reports it missing).
std::string ResolveLogPath(const std::string& path);

/// The format of the log at `path`, from its name and first bytes; a ParseError naming the file
/// when it is missing or no reader recognises it.
LogFormat DetectLogFormat(const std::string& path);

/// Reads any log into a Dataset (records in time order, the reference on its own channel): the
/// one entry point every command and scenario uses. `path` as ResolveLogPath takes it.
Dataset ReadLog(const std::string& path, const LogReadOptions& options = {});

}  // namespace slamrig::slam
