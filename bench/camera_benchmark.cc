// RGB-D camera speed (issue 11: a 640 x 480 RGB-D frame rendered on the CPU by MuJoCo through
// Mesa's surfaceless EGL, target >= 15 frames per second on two cores). Wall time is what counts
// here (llvmpipe renders on its own threads), so the benchmarks use real time; fps is frames per
// wall second. Run e.g.
//   build/bench/camera_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// and quote the median.

#include <benchmark/benchmark.h>

#include <cmath>

#include "sim/camera/rgbd_camera.h"
#include "sim/presets.h"
#include "sim/world_yaml.h"
#include "slam/texture/texture_map.h"

namespace slamrig::sim {
namespace {

// The robot's pose k frames into a lap of the office corridor (a slow circle through it).
Pose2 CorridorPose(int k) {
  const double s = 0.05 * k;
  return Pose2(3.0 + std::fmod(s, 17.0), 1.25, 0.02 * std::sin(s));
}

// range(0): depth camera offset in mm (0: one view serves both images; 25: the Kinect's two
// views); range(1): 1 = Kinect disparity noise, 0 = ideal depth.
void BM_RenderOffice(benchmark::State& state) {
  const WorldSpec world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  CameraSpec spec;  // the reports' Kinect, 640 x 480
  spec.depth_offset_x_m = static_cast<double>(state.range(0)) * 1e-3;
  spec.depth_model = state.range(1) != 0 ? DepthModel::kKinectDisparity : DepthModel::kIdeal;
  RgbdCamera camera(world, spec);
  int k = 0;
  for (auto _ : state) {
    RgbdFrame frame = camera.Render(CorridorPose(k++), Time());
    benchmark::DoNotOptimize(frame.depth_m.data());
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderOffice)
    ->ArgNames({"offset_mm", "kinect"})
    ->Args({25, 1})
    ->Args({0, 1})
    ->Args({0, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Texture mapping one 640 x 480 frame into a 5 cm colour map of the office.
void BM_TextureMapInsert(benchmark::State& state) {
  const WorldSpec world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  RgbdCamera camera(world, CameraSpec());
  const Pose2 pose = CorridorPose(10);
  const RgbdFrame frame = camera.Render(pose, Time());
  slam::TextureMapOptions options;
  options.min_m = {-1.0, -1.0};
  options.max_m = {25.0, 17.0};
  options.pixel_stride = static_cast<int>(state.range(0));
  slam::TextureMap map(options);
  for (auto _ : state) benchmark::DoNotOptimize(map.Insert(frame, pose));
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TextureMapInsert)->ArgName("stride")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamrig::sim

BENCHMARK_MAIN();
