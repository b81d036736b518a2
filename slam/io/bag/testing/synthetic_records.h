#pragma once

#include <cstdint>

#include "slam/io/dataset.h"

namespace slamrig::slam::testing {

/// Sensor streams shaped like the simulated office run, made without the simulator: a 1081-beam
/// scan (270 degrees) at 40 Hz with random ranges in mm steps and some no-returns at range_max,
/// IMU at 100 Hz, four-wheel encoder ticks at 40 Hz, odometry at 40 Hz, ground truth at 40 Hz.
/// Every double a bag stores as float32 (scan angles, increments, range limits) is
/// float-representable, so a bag round trip gives identical records. Deterministic in `seed`.
Dataset SyntheticRun(double duration_s, std::uint64_t seed, int beams = 1081);

}  // namespace slamrig::slam::testing
