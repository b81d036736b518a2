#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace slamrig::scenario {

/// Where the runs of a study (a sweep, a benchmark) execute.
enum class RunBackend {
  kLocal,  ///< child processes on this machine, `jobs` at a time
  kSlurm,  ///< one Slurm job array, a task per missing row (scenarios/slurm_sweep.h)
};

/// How to execute a study.
struct RunQueueOptions {
  std::string out_dir;         ///< results.csv, runs/<n>/ and the summary go here
  std::string slamrig_binary;  ///< the program every run and every Slurm task executes
  int jobs = 0;                ///< parallel runs; 0: one per core
  bool progress = true;        ///< progress bar with count and ETA on stderr
  RunBackend backend = RunBackend::kLocal;
  /// What a Slurm task runs: `slamrig <command> <spec_path> --out DIR --row K --quiet`.
  std::string command = "sweep";
  std::string spec_path;
  /// A run still going after this many seconds is killed and recorded as timed out (0: never).
  double timeout_s = 0.0;
};

/// One run of a study: a child `slamrig <args>` whose stdout goes to `dir`/log.txt.
struct QueuedRun {
  std::string id;                 ///< stable name, the first column of its results.csv row
  std::vector<std::string> args;  ///< after the program, e.g. {"run", "x.yaml", "--out", dir}
  std::string dir;                ///< its folder (created; metrics.json removed before it runs)
};

/// How a run's process ended.
struct RunEnd {
  int status = 0;            ///< wait status
  bool timed_out = false;    ///< killed at RunQueueOptions::timeout_s
  double wall_s = 0.0;       ///< from start to end
  double peak_rss_mb = 0.0;  ///< the child's peak resident memory (getrusage's ru_maxrss)
  std::string error_line;    ///< the last line it wrote to stderr, without slamrig's prefix
};

/// A study as the queue sees it: its runs, results.csv's header, and how a finished run becomes
/// a row. `row` returns the row's fields (the run's id first) and sets `*passed`.
struct RunQueueSpec {
  std::vector<QueuedRun> runs;
  std::vector<std::string> header;
  std::size_t status_column = 0;  ///< the column that reads "pass" for a run that passed
  std::function<std::vector<std::string>(std::size_t index, const RunEnd& end, bool* passed)> row;
  /// Written at the end (and after a Slurm array): the study's summary.
  std::function<void()> summarise;
};

/// What a study did.
struct RunQueueSummary {
  int total = 0;         ///< runs in the study
  int already_done = 0;  ///< found in results.csv from an earlier, interrupted study
  int ran = 0;           ///< run now
  int failed = 0;        ///< runs (now or before) that did not pass
};

/// Runs every run that results.csv does not already hold, `jobs` at a time (or as one Slurm
/// array), appending one CSV row per finished run at once (a single write, made durable), so a
/// study killed at any moment resumes with no run lost or run twice. A results.csv with another
/// header is a ConfigError, never mixed. A run stopped from outside (SIGTERM, SIGKILL, Ctrl-C)
/// leaves no row, so the next study runs it again; one that cannot write its folder stops the
/// study. At the end, results.csv's rows are put in the study's order (same study, same file)
/// and `spec.summarise` is called.
RunQueueSummary RunQueue(const RunQueueSpec& spec, const RunQueueOptions& options);

/// Runs row `row` alone and writes its results.csv line, under the header, to
/// `out_dir`/rows/<row>.csv atomically; results.csv is not touched (a Slurm task). Returns true
/// if the run passed.
bool RunQueueRow(const RunQueueSpec& spec, const RunQueueOptions& options, std::size_t row);

/// Where RunQueueRow writes row `row`: `out_dir`/rows/<row, 4 digits>.csv.
std::string QueueRowPath(const std::string& out_dir, std::size_t row);

/// "%.9g", or "" for a value that is not finite: a CSV cell.
std::string FormatCsvNumber(double v);

}  // namespace slamrig::scenario
