// World generation speed: a 60 x 40 m office with its route (target <= 0.2 s) and a
// 300 x 300 m campus (target <= 1 s), in memory (Generate) and with the map and picture
// (everything `slamrig world generate` makes but the file writes). Run e.g.
//   build/bench/worldgen_benchmark --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true
// and quote the median.

#include <benchmark/benchmark.h>

#include "sim/worldgen/worldgen.h"

namespace slamrig::sim::worldgen {
namespace {

GenerateSpec Spec(WorldKind kind) {
  GenerateSpec spec;
  spec.kind = kind;
  spec.seed = 7;
  spec.route = DefaultRouteOptions(kind);
  return spec;  // the defaults: a 60 x 40 m office, a 300 x 300 m campus
}

void BM_Generate(benchmark::State& state, WorldKind kind) {
  const GenerateSpec spec = Spec(kind);
  for (auto _ : state) benchmark::DoNotOptimize(Generate(spec));
}

void BM_GenerateWithMapAndPicture(benchmark::State& state, WorldKind kind) {
  const GenerateSpec spec = Spec(kind);
  for (auto _ : state) {
    const GeneratedWorld g = Generate(spec);
    benchmark::DoNotOptimize(MapPgm(RasteriseWalls(g)));
    benchmark::DoNotOptimize(RenderPng(g));
  }
}

BENCHMARK_CAPTURE(BM_Generate, office, WorldKind::kOffice)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Generate, campus, WorldKind::kCampus)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GenerateWithMapAndPicture, office, WorldKind::kOffice)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GenerateWithMapAndPicture, campus, WorldKind::kCampus)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamrig::sim::worldgen

BENCHMARK_MAIN();
