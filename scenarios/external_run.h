#pragma once

// The scenario runner's side of the `external` algorithm (slam/pipeline/external_estimator.h):
// the records a configuration was given written in its input format, the program run on them,
// and its trajectory (and map) read back and matched to the scans.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/external_estimator.h"
#include "slam/types/trajectory.h"

namespace slamrig::scenario {

/// What the input files say about the source besides its records.
struct ExternalSource {
  /// PARAM lines of a CARMEN input (the simulated lidar's range and mounting); empty for a log.
  std::vector<std::pair<std::string, std::string>> carmen_params;
  double ticks_per_revolution = 360.0;  ///< a bag's encoder resolution
};

/// What an external configuration produced, or why it failed.
struct ExternalOutcome {
  /// Empty when it ran and its output was read; else one line: what went wrong, with the
  /// last lines of the program's stderr where it wrote any.
  std::string failure;
  /// Its poses, one per scan, stamped with the scans' own times (the program's frame).
  Trajectory poses;
  /// Its map_server map (`<output stem>.yaml` beside `{output}`), when it wrote one.
  std::optional<slam::OccupancyGrid> map;
  double input_write_s = 0.0;  ///< wall time spent writing the input files
  double child_wall_s = 0.0;   ///< the program's wall time, start to exit
  long peak_rss_kb = 0;        ///< its peak resident memory (wait4's ru_maxrss)
  int exit_code = -1;          ///< its exit code; -1 when a signal ended it
};

/// Stamps in a program's TUM output match a scan when they are this close (seconds), or closer
/// when scans come closer together (half the smallest gap between two scans' distinct stamps).
inline constexpr double kExternalStampToleranceS = 1e-3;

/// Runs one external configuration in `work_dir` (the report folder): writes its records to
/// `work_dir/external/<name>/` in the configured format (`input.log` for CARMEN, the folder
/// `input` for the others), runs the command there with stdout and stderr to
/// `work_dir/<name>_stdout.txt` and `<name>_stderr.txt`, and reads `{output}`
/// (`work_dir/external/<name>/output.tum`). Everything that goes wrong with the program or its
/// output is `failure`; an unwritable folder is an OutputError, SIGINT/SIGTERM Interrupted (the
/// program is stopped first).
ExternalOutcome RunExternal(const std::string& name, const slam::ExternalEstimator& estimator,
                            const ExternalSource& source, const std::string& work_dir);

/// This process's resident memory now, KiB (0 when unknown).
long ProcessResidentKb();

/// The last `count` non-empty lines of a file, joined by " | " (at most 600 characters, its end).
std::string LastLines(const std::string& path, std::size_t count);

/// How a program ended, when that is a failure ("exit code 2", "killed by signal 6 (Aborted)",
/// "still running after timeout_s = 2 s; killed"); empty for exit code 0.
std::string ExternalEndFailure(bool timed_out, int status, double timeout_s);

/// Matches a program's poses to the scans' times, in order: one pose per scan, each within the
/// tolerance of its scan's stamp. Returns the poses stamped with the scans' times, or nullopt
/// and `*error` naming the counts or the first pose that does not match.
std::optional<Trajectory> MatchPosesToScans(const Trajectory& poses,
                                            const std::vector<Time>& scan_times,
                                            std::string* error);

}  // namespace slamrig::scenario
