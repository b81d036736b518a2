#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scenarios/benchmark_spec.h"

namespace slamrig::scenario {

/// One estimator on one dataset family: its runs' ATE distribution and failures.
struct LeaderboardCell {
  int runs = 0;      ///< rows in results.csv
  int failures = 0;  ///< status other than pass
  /// Failures the estimator did not itself report (its `diverged` verdict not 1): silent ones.
  int silent = 0;
  std::vector<double> ate;                    ///< ATE RMSE of the runs that have one, ascending
  double median = 0.0, p90 = 0.0, max = 0.0;  ///< of `ate` (linear interpolation); 0 when empty
};

/// One row of results.csv, for the worst-cases list.
struct BenchmarkCase {
  std::size_t run_index = 0;  ///< runs/<run_index>
  std::string id, status, failure;
  double ate_rmse_m = 0.0;  ///< NaN when the run has none
  /// The estimator's own verdict ("1", "0", empty when it gives none) and its lost seconds.
  std::string diverged, lost_s;
};

/// A benchmark's results.csv by estimator and dataset.
struct Leaderboard {
  std::vector<std::string> estimators, datasets;    ///< in the suite's order
  std::vector<std::vector<LeaderboardCell>> cells;  ///< [estimator][dataset]
  std::vector<BenchmarkCase> worst;                 ///< failures first, then by ATE, at most 10
  int missing = 0;                                  ///< runs of the suite with no row yet
};

/// The `q` quantile (0..1) of ascending `sorted` with linear interpolation between ranks
/// (Hyndman and Fan's type 7, numpy's default); 0 for an empty vector.
double Quantile(const std::vector<double>& sorted, double q);

/// Groups results.csv (`header`, `rows`) by the suite's estimators and datasets. Rows of runs
/// not in the suite are skipped. A pure function.
Leaderboard BuildLeaderboard(const BenchmarkSuite& suite, const std::vector<std::string>& header,
                             const std::vector<std::vector<std::string>>& rows);

/// Reads `out_dir`/results.csv and writes `out_dir`/summary.html: the leaderboard (estimator x
/// dataset: median, 90th percentile and maximum ATE, failures of runs), one plot per dataset of
/// each estimator's ATE over its runs, sorted (a quantile plot), and the worst cases linked to
/// their reports.
void WriteBenchmarkSummary(const BenchmarkSuite& suite, const std::string& out_dir);

}  // namespace slamrig::scenario
