// Speed of recording ROS 2 bags (issue 12, item 5): 60 simulated seconds of office-run-shaped
// streams (1081-beam scans at 40 Hz, IMU at 100 Hz, encoders, odometry and truth at 40 Hz, made
// without the simulator) written as a complete bag folder per iteration. `x_realtime` is
// simulated seconds written per wall-clock second. Run with
//   build/bench/bag_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// and quote the median.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "slam/io/bag/bag_writer.h"
#include "slam/io/bag/testing/synthetic_records.h"

namespace slamrig::slam {
namespace {

constexpr double kSeconds = 60.0;

const Dataset& Run() {
  static const Dataset data = testing::SyntheticRun(kSeconds, 42);
  return data;
}

void BM_WriteBag(benchmark::State& state, BagStorage storage, McapCompression compression) {
  const Dataset& data = Run();
  BagWriterOptions options;
  options.storage = storage;
  options.compression = compression;
  const std::string folder = (std::filesystem::temp_directory_path() /
                              ("slamrig_bag_benchmark_" + std::to_string(::getpid())))
                                 .string();
  std::filesystem::remove_all(folder);
  std::uintmax_t bytes = 0;
  for (auto _ : state) {
    WriteBag(data, folder, options);
    state.PauseTiming();
    bytes = 0;
    for (const auto& f : std::filesystem::directory_iterator(folder)) bytes += f.file_size();
    std::filesystem::remove_all(folder);
    state.ResumeTiming();
  }
  state.counters["x_realtime"] = benchmark::Counter(
      kSeconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["MB"] = static_cast<double>(bytes) * 1e-6;
}

BENCHMARK_CAPTURE(BM_WriteBag, mcap_zstd, BagStorage::kMcap, McapCompression::kZstd)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_WriteBag, mcap_lz4, BagStorage::kMcap, McapCompression::kLz4)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_WriteBag, mcap_none, BagStorage::kMcap, McapCompression::kNone)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_WriteBag, sqlite3, BagStorage::kSqlite3, McapCompression::kNone)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace slamrig::slam

BENCHMARK_MAIN();
