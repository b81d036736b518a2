#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scenarios/sweep_spec.h"
#include "scenarios/sweep_summary.h"

namespace slamrig::scenario {

/// Where the runs of a sweep execute.
enum class SweepBackend {
  kLocal,  ///< child processes on this machine, `jobs` at a time
  kSlurm,  ///< one Slurm job array, a task per missing row (scenarios/slurm_sweep.h)
};

/// How to execute a sweep.
struct SweepRunnerOptions {
  std::string out_dir;         ///< results.csv, runs/<n>/ and the summary plots go here
  std::string slamrig_binary;  ///< the program that runs one scenario (`slamrig run ...`)
  int jobs = 0;                ///< parallel runs; 0: one per core
  bool progress = true;        ///< progress bar with count and ETA on stderr
  SweepBackend backend = SweepBackend::kLocal;
  std::string sweep_path;  ///< the sweep file, passed on to the Slurm tasks (`--row K`)
};

/// What a sweep did.
struct SweepSummary {
  int total = 0;         ///< runs in the grid
  int already_done = 0;  ///< found in results.csv from an earlier, interrupted sweep
  int ran = 0;           ///< run now
  int failed = 0;        ///< runs (now or before) whose expectations failed or that errored
};

/// Runs every run of the grid that results.csv does not already hold, `jobs` at a time, each as
/// a child process `slamrig run SCENARIO --out runs/<n> --seed S --set key=value ... --quiet`,
/// appending one CSV row per finished run at once (a single write), so a sweep killed at any
/// moment resumes with no run lost or run twice. A results.csv written for another grid is an
/// error, never mixed. At the end writes summary.html (WriteSweepSummary).
SweepSummary RunSweep(const SweepSpec& spec, const SweepRunnerOptions& options);

/// Resolves the sweep's scenario at every value of the grid, as its runs will, before anything
/// runs or is written: each value alone (over the base scenario), then, for grids of at most
/// kMaxCheckedCombinations parameter combinations, every combination (two values each valid
/// alone may not be valid together; a larger grid meets those as failed runs). A bad value is a
/// ConfigError naming its place in the sweep file and the rule it breaks, so a typo in the grid
/// fails at once instead of as run 57 of an hour's study.
void CheckSweepGrid(const SweepSpec& spec);

/// The most parameter combinations CheckSweepGrid resolves one by one.
inline constexpr std::size_t kMaxCheckedCombinations = 4096;

/// Runs grid row `row` alone (a child `slamrig run` as in RunSweep) and writes its results.csv
/// line, under the header, to `out_dir`/rows/<row>.csv atomically; results.csv is not touched
/// (a Slurm task). Returns true if the run passed. Throws ConfigError for a row past the grid.
bool RunSweepRow(const SweepSpec& spec, const SweepRunnerOptions& options, std::size_t row);

/// Where RunSweepRow writes row `row`: `out_dir`/rows/<row, 4 digits>.csv.
std::string SweepRowPath(const std::string& out_dir, std::size_t row);

/// The CSV header of `spec`'s results file.
std::vector<std::string> ResultsHeader(const SweepSpec& spec,
                                       const std::vector<std::string>& metrics);

}  // namespace slamrig::scenario
