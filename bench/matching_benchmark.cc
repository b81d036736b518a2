// Scan matcher speed (issue 9): the correlative matcher's loop-closure search (a window of +-7 m
// and +-pi at 5 cm, a 1081-beam Hokuyo scan decimated to a few hundred points) and ICP, on the
// SegmentWorld office mapped from scans round its corridor loop (built once, outside the timing).
//
//   build/bench/matching_benchmark --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <numbers>

#include "slam/matching/correlative_matcher.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/scan_points.h"
#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

struct Office {
  SegmentWorld world = SegmentWorld::Office();
  OccupancyGrid grid{OccupancyGridOptions{}};
};

const Office& TheOffice() {
  static const Office* office = [] {
    auto* o = new Office;
    RandomEngine rng(1);
    auto insert = [&](double x, double y, double yaw) {
      const Pose2 pose(x, y, yaw);
      o->grid.InsertScan(o->world.Scan(pose, Time(), RangeFinderSpec{}, &rng), pose);
    };
    for (double x = 1.5; x <= 18.5; x += 0.5) insert(x, 1.5, 0.0);
    for (double y = 1.5; y <= 10.5; y += 0.5) insert(18.5, y, 1.57);
    for (double x = 18.5; x >= 1.5; x -= 0.5) insert(x, 10.5, 3.14);
    for (double y = 10.5; y >= 1.5; y -= 0.5) insert(1.5, y, -1.57);
    return o;
  }();
  return *office;
}

const Pose2 kTruth(9.2, 1.7, 0.4);

std::vector<Eigen::Vector2d> DecimatedScan(double voxel_m) {
  RandomEngine rng(2);
  ScanPointsOptions points;
  points.voxel_size_m = voxel_m;
  return ScanToBasePoints(TheOffice().world.Scan(kTruth, Time(), RangeFinderSpec{}, &rng), points);
}

// Args: window half-width in cm, angular window in mrad, voxel size in mm, depth.
void BM_CorrelativeSearch(benchmark::State& state) {
  CorrelativeMatcherOptions options;
  options.linear_window_m = static_cast<double>(state.range(0)) / 100.0;
  options.angular_window_rad =
      std::min(static_cast<double>(state.range(1)) / 1000.0, std::numbers::pi);
  options.branch_and_bound_depth = static_cast<int>(state.range(3));
  options.min_score = 0.4;
  const CorrelativeMatcher matcher(options, TheOffice().grid);
  const std::vector<Eigen::Vector2d> scan =
      DecimatedScan(static_cast<double>(state.range(2)) / 1000.0);
  const Pose2 initial(kTruth.x() + 0.8 * options.linear_window_m,
                      kTruth.y() - 0.3 * options.linear_window_m,
                      kTruth.theta() + 0.8 * options.angular_window_rad);
  int nodes = 0;
  double error_m = 0.0;
  for (auto _ : state) {
    const std::optional<MatchResult> m = matcher.Match(scan, initial);
    if (!m) {
      state.SkipWithError("no match");
      break;
    }
    nodes = m->iterations;
    error_m = (m->pose.translation() - kTruth.translation()).norm();
    benchmark::DoNotOptimize(m->pose);
  }
  state.counters["points"] = static_cast<double>(scan.size());
  state.counters["nodes"] = nodes;
  state.counters["error_m"] = error_m;
}
BENCHMARK(BM_CorrelativeSearch)
    ->Args({700, 3142, 100, 7})  // loop closure: +-7 m, +-pi
    ->Args({700, 3142, 60, 7})
    ->Args({300, 3142, 100, 7})
    ->Args({100, 500, 100, 5})  // local: +-1 m, +-0.5 rad
    ->Unit(benchmark::kMillisecond);

void BM_CorrelativePrecompute(benchmark::State& state) {
  CorrelativeMatcherOptions options;
  options.branch_and_bound_depth = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const CorrelativeMatcher matcher(options, TheOffice().grid);
    benchmark::DoNotOptimize(&matcher);
  }
  state.counters["cells"] = static_cast<double>(TheOffice().grid.log_odds().size());
}
BENCHMARK(BM_CorrelativePrecompute)->Arg(7)->Unit(benchmark::kMillisecond);

// Scan-to-scan ICP from a guess 5 cm and 3 degrees off. Arg: 0 point-to-point, 1 point-to-line.
void BM_IcpScanToScan(benchmark::State& state) {
  IcpOptions options;
  options.metric = state.range(0) == 0 ? IcpMetric::kPointToPoint : IcpMetric::kPointToLine;
  const std::vector<Eigen::Vector2d> ref = DecimatedScan(0.05);
  RandomEngine rng(3);
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  const Pose2 offset(0.04, -0.03, 0.05);
  const std::vector<Eigen::Vector2d> src = ScanToBasePoints(
      TheOffice().world.Scan(kTruth * offset, Time(), RangeFinderSpec{}, &rng), points);
  int iterations = 0;
  for (auto _ : state) {
    const IcpMatcher matcher(options, ref);  // the k-d tree and normals are part of the cost
    const std::optional<MatchResult> m = matcher.Match(src, Pose2());
    iterations = m ? m->iterations : -1;
    benchmark::DoNotOptimize(m);
  }
  state.counters["points"] = static_cast<double>(src.size());
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_IcpScanToScan)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace slamrig::slam

BENCHMARK_MAIN();
