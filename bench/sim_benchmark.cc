// Simulator speed (issue 3: office world, 1081-beam lidar at 40 Hz, IMU at 100 Hz, encoders at
// 40 Hz, physics at >= 200 Hz: >= 300x real time on one core). The x_real_time counter is
// simulated seconds per second of CPU time. Run e.g.
//   build/bench/sim_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// and quote the median.

#include <benchmark/benchmark.h>
#include <box2d/box2d.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "sim/presets.h"
#include "sim/ray_caster.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world.h"
#include "sim/world_yaml.h"

namespace slamrig::sim {
namespace {

SimulatorOptions Office() {
  SimulatorOptions options;
  options.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  options.robot = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  options.world.drive.laps = 1000;  // never finishes within a benchmark
  return options;
}

// The whole simulator: 10 simulated seconds per iteration, driving the office loop.
void BM_SimulateOffice(benchmark::State& state) {
  SimulatorOptions options = Office();
  options.physics_rate_hz = static_cast<double>(state.range(0));
  Simulator sim(options);
  constexpr double kSecondsPerIteration = 10.0;
  std::size_t records = 0;
  for (auto _ : state) {
    const double until = sim.time().seconds() + kSecondsPerIteration;
    while (sim.time().seconds() < until - 1e-9) records += sim.Step().records.size();
  }
  state.counters["x_real_time"] = benchmark::Counter(
      kSecondsPerIteration * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["records"] = static_cast<double>(records);
}
BENCHMARK(BM_SimulateOffice)->Arg(200)->Arg(400)->Unit(benchmark::kMillisecond);

// The same without sensors: what the physics (Box2D, tyres, motors, driver) costs alone.
void BM_SimulateOfficePhysicsOnly(benchmark::State& state) {
  SimulatorOptions options = Office();
  options.robot.lidar.enabled = false;
  options.robot.imu.enabled = false;
  options.robot.encoders.enabled = false;
  Simulator sim(options);
  constexpr double kSecondsPerIteration = 10.0;
  for (auto _ : state) {
    const double until = sim.time().seconds() + kSecondsPerIteration;
    while (sim.time().seconds() < until - 1e-9) sim.Step();
  }
  state.counters["x_real_time"] = benchmark::Counter(
      kSecondsPerIteration * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateOfficePhysicsOnly)->Unit(benchmark::kMillisecond);

// One 1081-beam, 270-degree scan from a corridor corner of the office.
std::vector<Ray> OfficeFan() {
  std::vector<Ray> rays(1081);
  const Eigen::Vector2d origin(22.0, 2.0);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double angle =
        0.7 - 0.75 * std::numbers::pi + static_cast<double>(i) * 0.25 * std::numbers::pi / 180.0;
    rays[i] = {origin, {std::cos(angle), std::sin(angle)}, angle};
  }
  return rays;
}

void BM_CasterScan(benchmark::State& state) {
  World world(Office().world);
  RayCaster caster(world.b2world());
  const std::vector<Ray> rays = OfficeFan();
  std::vector<double> ranges(rays.size());
  for (auto _ : state) {
    caster.Cast(rays, 30.0, ranges);
    benchmark::DoNotOptimize(ranges.data());
  }
  state.counters["ns_per_beam"] =
      benchmark::Counter(static_cast<double>(rays.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CasterScan)->Unit(benchmark::kMicrosecond);

// The same scan through b2World::RayCast, one call per beam (the baseline the caster replaces).
class Closest : public b2RayCastCallback {
 public:
  float ReportFixture(b2Fixture*, const b2Vec2&, const b2Vec2&, float fraction) override {
    fraction_ = fraction;
    return fraction;
  }
  float fraction_ = 1.0f;
};

void BM_Box2dRayCastScan(benchmark::State& state) {
  World world(Office().world);
  const std::vector<Ray> rays = OfficeFan();
  std::vector<double> ranges(rays.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < rays.size(); ++i) {
      Closest hit;
      const Eigen::Vector2d end = rays[i].origin + 30.0 * rays[i].direction;
      world.b2world()->RayCast(
          &hit,
          b2Vec2(static_cast<float>(rays[i].origin.x()), static_cast<float>(rays[i].origin.y())),
          b2Vec2(static_cast<float>(end.x()), static_cast<float>(end.y())));
      ranges[i] = 30.0 * hit.fraction_;
    }
    benchmark::DoNotOptimize(ranges.data());
  }
  state.counters["ns_per_beam"] =
      benchmark::Counter(static_cast<double>(rays.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Box2dRayCastScan)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace slamrig::sim

BENCHMARK_MAIN();
