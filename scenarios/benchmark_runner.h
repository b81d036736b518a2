#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "scenarios/benchmark_spec.h"
#include "scenarios/run_queue.h"

namespace slamrig::scenario {

/// results.csv's columns: the run, its verdict and why, the figures, and (last) the three that
/// depend on the machine (left out when two benchmarks' results are compared).
const std::vector<std::string>& BenchmarkHeader();

/// The columns of BenchmarkHeader that depend on the machine, not the inputs.
const std::vector<std::string>& BenchmarkTimingColumns();

/// A run's figures, as read from its metrics.json (absent ones not in the map).
struct BenchmarkFigures {
  std::map<std::string, double> estimator;  ///< ate_rmse_m, ate_max_m, ... of the estimator
  double baseline_ate_rmse_m = -1.0;        ///< dead reckoning's on the same data; < 0: none
  /// Why the estimator produced nothing (an external program's failure), else empty.
  std::string failure;
};

/// The verdict of a run that produced figures: "pass", or "fail" with the reason when its ATE is
/// above `fail_above_m` (the suite's; dead reckoning's on the same data is named beside it, but
/// does not raise the bound: an estimator 8 m off where dead reckoning is 13 m off has failed), or
/// when it has no ATE at all.
std::string JudgeBenchmarkRun(const BenchmarkFigures& figures, double fail_above_m,
                              std::string* reason);

/// Runs every run of the suite that DIR/results.csv does not already hold (RunQueue: in
/// parallel or as a Slurm array, resumable), each a child `slamrig run runs/<n>/scenario.yaml
/// --out runs/<n> --quiet` killed at the suite's timeout. A run fails when it crashes, times
/// out, errors, or its ATE is above the suite's fail_above_m. Writes summary.html at the
/// end (WriteBenchmarkSummary).
RunQueueSummary RunBenchmark(const BenchmarkSuite& suite, RunQueueOptions options);

/// Runs row `row` alone (a Slurm task, RunQueueRow).
bool RunBenchmarkRow(const BenchmarkSuite& suite, RunQueueOptions options, std::size_t row);

}  // namespace slamrig::scenario
