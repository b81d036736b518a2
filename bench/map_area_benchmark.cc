// Cost per update against map area (issue 13, part 4: "time per update within 1.5x from a 500 m^2
// map to a 5,000 m^2 one"). One scan stream, simulated once outside the timing (the SegmentWorld
// office, 20 m x 12 m, Hokuyo 1081 beams at 40 Hz, two laps); only the area of the map it is
// written into varies:
//  - BM_FieldUpdate/AREA/MODE: one map update (insert the scan at its true pose) plus bringing
//    the likelihood field up to date over the scan's reach, on a map loaded at AREA m^2 around
//    the office. MODE 0 recomputes the window (LikelihoodField::Update, the filter's method before
//    Follow), MODE 1 follows the map's changes over a window that slides with the robot
//    (LikelihoodField::Follow(grid, window) + view(window)).
//  - BM_PfUpdate/AREA: the default particle filter (100 particles, one thread) through the
//    Estimator interface, its map given room (map.grow_margin_m) to reach about AREA m^2; time per
//    filter update (the scans it scored), map area reached as a counter.
//
//   build/bench/map_area_benchmark --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/likelihood_field.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pf/testing/synthetic_run.h"
#include "slam/pipeline/particle_filter_estimator.h"

namespace slamrig::slam {
namespace {

struct OfficeRun {
  std::vector<SyncedScan> scans;
  std::vector<Pose2> truth;       // in the frame of the first scan (the filter's map frame)
  Eigen::Vector2d office_centre;  // in that frame
};

const OfficeRun& Run() {
  static const OfficeRun* run = [] {
    testing::SyntheticRunOptions options;
    options.waypoints = testing::OfficeLoop();
    options.laps = 2;
    testing::SyntheticRun synthetic =
        testing::MakeSyntheticRun(testing::SegmentWorld::Office(), options);
    auto* r = new OfficeRun;
    r->scans = SyncToScans(synthetic.records, ScanSyncOptions{}).scans;
    const Pose2 anchor_inverse = synthetic.truth.front().map_from_base.Inverse();
    for (const GroundTruthPose& t : synthetic.truth) {
      r->truth.push_back(anchor_inverse * t.map_from_base);
    }
    r->office_centre = anchor_inverse * Eigen::Vector2d(10.0, 6.0);
    return r;
  }();
  return *run;
}

// Side of a square of `area_m2`.
double Side(double area_m2) { return std::sqrt(area_m2); }

void BM_FieldUpdate(benchmark::State& state) {
  const OfficeRun& run = Run();
  const double area_m2 = static_cast<double>(state.range(0));
  const bool follow = state.range(1) == 1;
  const ParticleFilterOptions pf;  // the filter's map and field settings
  // A square map of the given area, the office (in the first scan's frame) near its middle.
  const int cells = static_cast<int>(std::lround(Side(area_m2) / pf.map.resolution_m));
  const Eigen::Vector2d origin = run.office_centre - Eigen::Vector2d::Constant(0.5 * Side(area_m2));
  const double reach = pf.points.max_range_m + 1.0;
  int updates = 0;
  double grid_area_m2 = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    OccupancyGrid grid(pf.map, origin, cells, cells);
    LikelihoodField field(pf.likelihood_field);
    state.ResumeTiming();
    // Every 20th scan: where the filter updates at 0.5 m/s and 0.25 m.
    for (std::size_t i = 0; i < run.scans.size(); i += 20) {
      grid.InsertScan(run.scans[i].scan, run.truth[i]);
      const Eigen::Vector2d m = Eigen::Vector2d::Constant(reach);
      const Eigen::AlignedBox2d window(run.truth[i].translation() - m,
                                       run.truth[i].translation() + m);
      if (follow) {
        field.Follow(grid, window);
        benchmark::DoNotOptimize(field.view(window).values);
      } else {
        field.Update(grid, window);
        benchmark::DoNotOptimize(field.view().values);
      }
      ++updates;
    }
    grid_area_m2 = grid.width() * grid.height() * pf.map.resolution_m * pf.map.resolution_m;
  }
  state.counters["map_area_m2"] = grid_area_m2;
  state.counters["time_per_update"] =
      benchmark::Counter(static_cast<double>(updates) * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FieldUpdate)
    ->ArgsProduct({{500, 5000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_PfUpdate(benchmark::State& state) {
  const OfficeRun& run = Run();
  const double area_m2 = static_cast<double>(state.range(0));
  ParticleFilterOptions options;
  // Room around the 20 m x 12 m office so that (20 + 2g)(12 + 2g) is about the area.
  options.map.grow_margin_m = (-32.0 + std::sqrt(32.0 * 32.0 - 4.0 * (240.0 - area_m2))) / 4.0;
  double updates = 0.0, map_area_m2 = 0.0;
  for (auto _ : state) {
    EstimatorContext context;
    context.seed = 1;
    ParticleFilterEstimator estimator(options, context);
    for (const SyncedScan& s : run.scans) benchmark::DoNotOptimize(estimator.AddScan(s).pose);
    updates += estimator.Statistics().at("updates");
    const OccupancyGrid& map = estimator.map();
    map_area_m2 = map.width() * map.height() * map.resolution() * map.resolution();
  }
  state.counters["map_area_m2"] = map_area_m2;
  state.counters["time_per_update"] =
      benchmark::Counter(updates, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PfUpdate)->Arg(500)->Arg(5000)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace
}  // namespace slamrig::slam

BENCHMARK_MAIN();
