// Occupancy mapping of a whole real log (issue: all 910 intel-corrected scans at 5 cm < 0.5 s).

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>

#include "slam/grid/occupancy_grid.h"
#include "slam/io/carmen_reader.h"
#include "slam/io/log_reader.h"

namespace slamrig {
namespace {

std::string IntelPath() {
  const char* env = std::getenv("SLAMRIG_DATA_DIR");
  const std::filesystem::path dir =
      env != nullptr ? std::filesystem::path(env)
                     : std::filesystem::path(SLAMRIG_SOURCE_DIR) / ".." / "shared" / "datasets";
  return (dir / "carmen_corrected" / "intel-corrected.log.gz").string();
}

// Inserting every scan into a fresh 5 cm grid (the log is parsed once, outside the timing).
void BM_MapIntelScans(benchmark::State& state) {
  const slam::CarmenLog log = slam::ReadCarmenLog(IntelPath());
  slam::OccupancyGridOptions options;
  options.resolution_m = 0.05;
  for (auto _ : state) {
    slam::OccupancyGrid grid(options);
    for (const auto& s : log.scans) grid.InsertScan(s.scan, s.logged_pose);
    benchmark::DoNotOptimize(grid.num_tiles());
  }
  state.counters["scans"] = static_cast<double>(log.scans.size());
}
BENCHMARK(BM_MapIntelScans)->Unit(benchmark::kMillisecond);

// Parsing the gzip log into records and reference, as `slamrig slam` and `slamrig run` read
// any log (ReadLog): the command line's side of bench/python_timing.py's read figure.
void BM_ReadLogIntel(benchmark::State& state) {
  const std::string path = IntelPath();
  for (auto _ : state) {
    const slam::Dataset data = slam::ReadLog(path);
    benchmark::DoNotOptimize(data.records.data());
  }
}
BENCHMARK(BM_ReadLogIntel)->Unit(benchmark::kMillisecond);

// Parsing the gzip log plus mapping: what `slamrig map` spends before writing files.
void BM_ReadAndMapIntel(benchmark::State& state) {
  const std::string path = IntelPath();
  slam::OccupancyGridOptions options;
  options.resolution_m = 0.05;
  for (auto _ : state) {
    const slam::CarmenLog log = slam::ReadCarmenLog(path);
    slam::OccupancyGrid grid(options);
    for (const auto& s : log.scans) grid.InsertScan(s.scan, s.logged_pose);
    benchmark::DoNotOptimize(grid.num_tiles());
  }
}
BENCHMARK(BM_ReadAndMapIntel)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamrig

BENCHMARK_MAIN();
