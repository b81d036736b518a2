#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace slamrig::scenario {

/// One swept scenario key and the values it takes (kept as YAML text, applied with --set).
struct SweepParameter {
  std::string key;                  ///< dotted path into the scenario file, e.g. slam.pf.particles
  std::vector<std::string> values;  ///< YAML scalars, e.g. "0.01", "100"
  std::vector<std::string> where;   ///< each value's place in the sweep file, "file:line:col"
};

/// A sweep file: a base scenario, a grid of parameters and a set of seeds.
///
/// ```yaml
/// scenario: ../office_loop.yaml      # relative to the sweep file
/// seeds: 5                           # 1..5, or a list [3, 7, 11]
/// parameters:                        # the grid: every combination, in this order
///   robot.lidar.range_noise_stddev_m: [0.01, 0.03, 0.1]
///   slam.pf.particles: [30, 100, 300]
/// metrics: [pf.ate_rmse_m, pf.realtime_factor]   # optional; config.metric of metrics.json
/// ```
struct SweepSpec {
  std::string path;           ///< the sweep file
  std::string scenario_path;  ///< resolved against the sweep file's folder
  std::vector<std::uint64_t> seeds;
  std::vector<SweepParameter> parameters;
  /// Columns of results.csv. Empty: every metric the first finished run reports except the
  /// wall-clock ones (realtime_factor), so that a re-run sweep gives identical rows.
  std::vector<std::string> metrics;
};

/// One run of the grid.
struct SweepRun {
  std::string id;                        ///< stable name: "p0=0.01 p1=100 seed=3" style
  std::vector<std::size_t> value_index;  ///< per parameter
  std::uint64_t seed = 0;
};

/// The most runs a sweep grid may have (seeds times every parameter's value count).
inline constexpr std::size_t kMaxSweepRuns = 1'000'000;

/// Reads a sweep file strictly (unknown keys, wrong types, empty lists and grids of more than
/// kMaxSweepRuns runs are ConfigErrors with file:line and key).
SweepSpec LoadSweepSpec(const std::string& path);

/// Every combination of parameter values times every seed, in a fixed order.
std::vector<SweepRun> ExpandSweep(const SweepSpec& spec);

/// Moves `index` (one value index per parameter, all 0 at the grid's first point) to the next
/// combination of parameter values, the last parameter fastest. False, with `index` back at the
/// first point, when it was the last (at once for a grid without parameters).
bool NextGridPoint(const SweepSpec& spec, std::vector<std::size_t>* index);

}  // namespace slamrig::scenario
