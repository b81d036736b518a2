// Particle-filter SLAM speed (issue 4: a simulated ECE276A-like run of 5,000 scans x 1081 beams,
// 100 particles, the reports' 9x9 shift search, on one core, in <= 30 s; the reports' Python took
// about 1.5 h). The run is simulated once (SegmentWorld office, kinematic robot, encoders and
// Hokuyo at 40 Hz, gyro at 100 Hz), outside the timing.
//
//   build-pf/bench/pf_benchmark --benchmark_filter=ReportsPreset
#include <benchmark/benchmark.h>

#include <cmath>

#include "slam/matching/map_correlator.h"
#include "slam/matching/scan_points.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/particle_filter.h"
#include "slam/pf/testing/synthetic_run.h"
#include "slam/pipeline/particle_filter_estimator.h"

namespace slamrig::slam {
namespace {

struct Ece276aLikeRun {
  std::vector<SyncedScan> scans;  // the estimator's input, synchronised outside the timing
  std::vector<GroundTruthPose> truth;
};

// 5,000 Hokuyo scans (1081 beams, 270 degrees, 30 m) at 40 Hz: 125 s round the office loop.
const Ece276aLikeRun& Run() {
  static const Ece276aLikeRun* run = [] {
    testing::SyntheticRunOptions options;
    options.waypoints = testing::OfficeLoop();
    options.laps = 10;
    options.max_duration_s = 4999.5 / 40.0;
    testing::SyntheticRun synthetic =
        testing::MakeSyntheticRun(testing::SegmentWorld::Office(), options);
    auto* r = new Ece276aLikeRun;
    r->scans = SyncToScans(synthetic.records, ScanSyncOptions{}).scans;
    r->truth = std::move(synthetic.truth);
    return r;
  }();
  return *run;
}

double PositionRmse(const Trajectory& estimate, const std::vector<GroundTruthPose>& truth) {
  const Pose2 anchor = truth.front().map_from_base;
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    sum += ((anchor * estimate[i].pose).translation() - truth[i].map_from_base.translation())
               .squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(estimate.size()));
}

void RunWhole(benchmark::State& state, ParticleFilterOptions options) {
  const Ece276aLikeRun& run = Run();
  options.num_particles = 100;
  options.num_threads = static_cast<int>(state.range(0));
  double rmse = 0.0;
  for (auto _ : state) {
    // Through the Estimator interface, as every command runs it.
    EstimatorContext context;
    context.seed = 1;
    ParticleFilterEstimator estimator(options, context);
    Trajectory trajectory;
    for (const SyncedScan& s : run.scans) trajectory.Append(s.scan.time, estimator.AddScan(s).pose);
    rmse = PositionRmse(trajectory, run.truth);
    benchmark::DoNotOptimize(estimator.map().DenseLogOdds().data());
  }
  state.counters["scans"] = static_cast<double>(run.scans.size());
  state.counters["beams"] = static_cast<double>(run.scans.front().scan.ranges_m.size());
  state.counters["position_rmse_m"] = rmse;
  state.counters["ms_per_scan"] = benchmark::Counter(
      static_cast<double>(run.scans.size()) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// The reports' method: all 1081 beams, 9x9 x/y shifts, Gaussian noise, per-beam map updates.
void BM_ReportsPreset(benchmark::State& state) {
  RunWhole(state, ParticleFilterOptions::ReportsPreset());
}
BENCHMARK(BM_ReportsPreset)->Arg(1)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// The improved defaults (likelihood field, 9x9x9 x/y/yaw search, refinement).
void BM_ImprovedDefaults(benchmark::State& state) { RunWhole(state, ParticleFilterOptions{}); }
BENCHMARK(BM_ImprovedDefaults)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

// One 9x9 map correlation of a 1081-beam scan against a mapped office.
void BM_Correlate9x9(benchmark::State& state) {
  const Ece276aLikeRun& run = Run();
  OccupancyGrid grid(OccupancyGridOptions{});
  const Pose2 anchor_inverse = run.truth.front().map_from_base.Inverse();
  for (std::size_t i = 0; i < 400; i += 10) {
    grid.InsertScan(run.scans[i].scan, anchor_inverse * run.truth[i].map_from_base);
  }
  ScanPointsOptions point_options;
  point_options.voxel_size_m = static_cast<double>(state.range(0)) / 100.0;
  const std::vector<Eigen::Vector2d> points = ScanToBasePoints(run.scans[200].scan, point_options);
  const MapCorrelator correlator(MapCorrelatorOptions{});
  const Pose2 pose = anchor_inverse * run.truth[200].map_from_base;
  const std::vector<float> values = grid.DenseLogOdds();
  const GridView view{values.data(), grid.width(), grid.height(), grid.origin(), grid.resolution()};
  for (auto _ : state) {
    benchmark::DoNotOptimize(correlator.Correlate(view, points, pose));
  }
  state.counters["points"] = static_cast<double>(points.size());
}
BENCHMARK(BM_Correlate9x9)->Arg(0)->Arg(5)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace slamrig::slam

BENCHMARK_MAIN();
