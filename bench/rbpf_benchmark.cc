// Rao-Blackwellised PF speed and memory: per-update time and the tiles the per-particle maps hold,
// on a simulated run (two laps of the SegmentWorld office loop, 271-beam lidar at 10 Hz, the
// second lap closing the loop), simulated once outside the timing. Peak RSS of a whole real log is
// measured with /usr/bin/time -v on `slamrig slam` (README, "Rao-Blackwellised particle filter").
//
//   build/bench/rbpf_benchmark --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <string>

#include "slam/odometry/scan_sync.h"
#include "slam/pf/rbpf.h"
#include "slam/pf/testing/synthetic_run.h"

namespace slamrig::slam {
namespace {

struct OfficeRun {
  std::vector<SyncedScan> scans;
  std::vector<GroundTruthPose> truth;
};

const OfficeRun& Run() {
  static const OfficeRun* run = [] {
    testing::SyntheticRunOptions options;
    options.waypoints = testing::OfficeLoop();
    options.laps = 2;
    options.scan_rate_hz = 10.0;
    options.lidar.num_beams = 271;
    options.lidar.angle_increment_rad = 1.0 * 3.14159265358979 / 180.0;
    testing::SyntheticRun synthetic =
        testing::MakeSyntheticRun(testing::SegmentWorld::Office(), options);
    auto* r = new OfficeRun;
    r->scans = SyncToScans(synthetic.records, ScanSyncOptions{}).scans;
    r->truth = std::move(synthetic.truth);
    return r;
  }();
  return *run;
}

// The process's peak resident set (VmHWM), MB; 0 where /proc is not there.
double PeakRssMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

void BM_RbpfOfficeTwoLaps(benchmark::State& state) {
  const OfficeRun& run = Run();
  RbpfOptions options;
  options.num_particles = static_cast<int>(state.range(0));
  options.num_threads = static_cast<int>(state.range(1));
  int updates = 0;
  int tiles = 0;
  int tiles_per_map = 0;
  double rmse = 0.0;
  for (auto _ : state) {
    Rbpf filter(options);
    const Pose2 anchor = run.truth.front().map_from_base;
    double sum = 0.0;
    for (std::size_t i = 0; i < run.scans.size(); ++i) {
      const RbpfStep step = filter.AddScan(run.scans[i].scan, run.scans[i].increment);
      sum += ((anchor * step.best_pose).translation() - run.truth[i].map_from_base.translation())
                 .squaredNorm();
    }
    rmse = std::sqrt(sum / static_cast<double>(run.scans.size()));
    updates = filter.update_count();
    tiles = filter.DistinctTiles();
    tiles_per_map = filter.best().map.num_tiles();
  }
  state.counters["updates"] = updates;
  state.counters["position_rmse_m"] = rmse;
  state.counters["ms_per_update"] = benchmark::Counter(
      static_cast<double>(updates) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["map_tiles"] = tiles;
  // Without sharing every particle would hold a whole map.
  state.counters["tiles_unshared"] = static_cast<double>(tiles_per_map) * options.num_particles;
  state.counters["map_mb"] = tiles * sizeof(TiledGrid::Tile) / 1048576.0;
  state.counters["peak_rss_mb"] = PeakRssMb();
}
BENCHMARK(BM_RbpfOfficeTwoLaps)
    ->Args({30, 1})
    ->Args({100, 2})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
}  // namespace slamrig::slam

BENCHMARK_MAIN();
