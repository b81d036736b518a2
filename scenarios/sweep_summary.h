#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scenarios/sweep_spec.h"

namespace slamrig::scenario {

/// results.csv's fields: RFC 4180 quoting (a field with a comma, quote or newline is quoted).
std::string JoinCsv(const std::vector<std::string>& fields);
std::vector<std::string> SplitCsv(const std::string& line);
/// A results.csv cell as a number: NaN for an empty cell or one that is not wholly a number.
double CsvNumber(const std::string& cell);

/// `out_dir`/runs/<index, 4 digits>: the folder of grid row `index` (ExpandSweep order).
std::string RunDir(const std::string& out_dir, std::size_t index);

/// One expectation of a run as its metrics.json states it.
struct ExpectationResult {
  std::string name;  ///< "pf.ate_rmse_m_max"
  double value = 0.0;
  double threshold = 0.0;
  bool passed = false;
};

/// One seed's run at a grid point.
struct SeedResult {
  std::uint64_t seed = 0;
  std::size_t run_index = 0;  ///< its grid row: runs/<run_index>
  std::string status;         ///< pass, fail or error from results.csv; "" when not run yet
  std::vector<ExpectationResult> failed;  ///< its failed expectations (status fail)
};

/// The mean, min and max of a metric over the seeds that reported it.
struct MetricStats {
  double mean = 0.0, min = 0.0, max = 0.0;
  int count = 0;
};

/// One combination of parameter values.
struct GridPoint {
  std::vector<std::size_t> value_index;  ///< per parameter
  std::vector<SeedResult> seeds;         ///< in the sweep's seed order
  std::map<std::string, MetricStats> metrics;
};

/// A sweep's results by grid point, in ExpandSweep order.
struct SweepAggregate {
  std::vector<std::size_t> swept;    ///< parameters that take more than one value
  std::vector<std::string> metrics;  ///< the metric columns of results.csv
  std::vector<GridPoint> points;
  int passed = 0, failed = 0, errors = 0, missing = 0;  ///< runs
};

/// Groups results.csv (`header`, `rows`) by grid point. Rows of another grid (values not in
/// `spec`) and of the wrong width are skipped. `expectations` holds the expectations of runs by
/// grid row (read from their metrics.json); a failed run's failed ones are kept. A pure function.
SweepAggregate AggregateSweep(
    const SweepSpec& spec, const std::vector<std::string>& header,
    const std::vector<std::vector<std::string>>& rows,
    const std::map<std::size_t, std::vector<ExpectationResult>>& expectations);

/// The expectations in a run's metrics.json (its "expectations" object); empty when the file is
/// missing or unreadable.
std::vector<ExpectationResult> ReadRunExpectations(const std::string& metrics_json);

/// Reads `out_dir`/results.csv and each failed run's metrics.json and writes summary.html: a
/// plot per metric against the one swept parameter, a heat map per metric when two are swept
/// (one plot per swept parameter when more are), a table with a row per grid point (each seed's
/// verdict linked to its run's report, and the failed expectations with value and bound), and
/// for NEES metrics the ANEES against its chi-square region. Returns the number of PNG plots.
int WriteSweepSummary(const SweepSpec& spec, const std::string& out_dir);

}  // namespace slamrig::scenario
