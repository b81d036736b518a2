#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scenarios/run_queue.h"
#include "scenarios/sweep_spec.h"
#include "scenarios/sweep_summary.h"

namespace slamrig::scenario {

/// Runs every run of the grid that results.csv does not already hold (RunQueue: in parallel or
/// as a Slurm array, resumable), each a child `slamrig run SCENARIO --out runs/<n> --seed S
/// --set key=value ... --quiet`. At the end writes summary.html (WriteSweepSummary).
RunQueueSummary RunSweep(const SweepSpec& spec, const RunQueueOptions& options);

/// Resolves the sweep's scenario at every value of the grid, as its runs will, before anything
/// runs or is written: each value alone (over the base scenario), then, for grids of at most
/// kMaxCheckedCombinations parameter combinations, every combination (two values each valid
/// alone may not be valid together; a larger grid meets those as failed runs). A bad value is a
/// ConfigError naming its place in the sweep file and the rule it breaks, so a typo in the grid
/// fails at once instead of as run 57 of an hour's study.
void CheckSweepGrid(const SweepSpec& spec);

/// The most parameter combinations CheckSweepGrid resolves one by one.
inline constexpr std::size_t kMaxCheckedCombinations = 4096;

/// Runs grid row `row` alone (RunQueueRow: a Slurm task). Returns true if the run passed. Throws
/// ConfigError for a row past the grid.
bool RunSweepRow(const SweepSpec& spec, const RunQueueOptions& options, std::size_t row);

/// The CSV header of `spec`'s results file.
std::vector<std::string> ResultsHeader(const SweepSpec& spec,
                                       const std::vector<std::string>& metrics);

}  // namespace slamrig::scenario
