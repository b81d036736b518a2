#pragma once

#include <string>
#include <vector>

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
  /// A log cut short (a crashed recording: an MCAP file without its footer, a sqlite3 bag with
  /// pages missing, a CARMEN log whose last line or gzip stream is cut) is an error, instead of
  /// read up to the cut with Dataset::truncated saying where it stopped.
  bool strict = false;
  /// ROS 2 bags: the topics to read (the ROS defaults BagWriter writes).
  BagTopicNames topics;
};

/// The datasets folder: $SLAMRIG_DATA_DIR, else ../shared/datasets of the current folder when it
/// exists, else ../shared/datasets beside the source tree slamrig was built from.
std::string DataDir();

/// `path` itself when it exists (or names an ECE276A dataset), else `path` inside DataDir() when
/// that exists (`carmen_corrected/intel-corrected.log.gz`), else `path` unchanged (the reader then
/// reports it missing). A folder that is neither a bag nor an ECE276A dataset but holds exactly
/// one run (what `slamrig simulate` writes: DIR/run.log, the bag folder DIR/run, or an ECE276A
/// dataset's files) resolves to that run; with none or several DetectLogFormat lists them.
std::string ResolveLogPath(const std::string& path);

/// The runs a folder holds, sorted: its *.log and *.log.gz files, its sub-folders that are ROS 2
/// bags, and DIR/NUMBER for each ECE276A encoder file (Encoders20.npz, encoders20.csv.gz).
std::vector<std::string> RunsInFolder(const std::string& folder);

/// The format of the log at `path`, from its name and first bytes; a ParseError naming the file
/// when it is missing or no reader recognises it, saying what it is not ("x.bin: not a log: no
/// MCAP magic, no SQLite header, not gzip, not text"), or for a folder what it holds.
LogFormat DetectLogFormat(const std::string& path);

/// Reads any log into a Dataset (records in time order, the reference on its own channel): the
/// one entry point every command and scenario uses. `path` as ResolveLogPath takes it.
Dataset ReadLog(const std::string& path, const LogReadOptions& options = {});

}  // namespace slamrig::slam
