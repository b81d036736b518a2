#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scenarios/run_queue.h"

namespace slamrig::scenario {

/// Runs grid rows `rows` (ascending) of a sweep as one Slurm job array: `sbatch --array=<rows>`
/// with a task per row, each running `slamrig sweep SWEEP --out DIR --row K --quiet` (which
/// writes DIR/rows/<K>.csv atomically), then follows the job with `squeue` until no task is left.
/// Returns, per row, its results.csv line (empty when the task left no row file, e.g. it was
/// cancelled). Job script and task logs go to DIR/slurm/. sbatch's own environment variables
/// (SBATCH_PARTITION, SBATCH_TIMELIMIT, ...) choose where the tasks run. Throws
/// std::runtime_error when sbatch fails. On SIGINT/SIGTERM (Ctrl-C) cancels the array
/// (`scancel`), waits for its tasks to leave the queue and throws Interrupted; the rows that
/// were not finished stay missing, so the next sweep submits them again.
std::vector<std::string> RunRowsOnSlurm(const RunQueueOptions& options,
                                        const std::vector<std::size_t>& rows);

/// Where the task of grid row `row` logs: `out_dir`/slurm/task_<row>.log.
std::string SlurmTaskLogPath(const std::string& out_dir, std::size_t row);

/// Slurm's compact form of ascending indices: {0, 1, 2, 5, 7, 8} -> "0-2,5,7-8".
std::string SlurmArrayIndices(const std::vector<std::size_t>& rows);

}  // namespace slamrig::scenario
