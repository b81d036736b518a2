#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace slamrig {

/// A named pseudo-random stream: xoshiro256** (Blackman and Vigna, "Scrambled linear
/// pseudorandom number generators", 2021) seeded from (seed, name) through SplitMix64 over the
/// FNV-1a hash of the name. Each noise source owns one stream, so adding or removing a sensor never
/// shifts another sensor's noise. Every distribution is implemented here (not <random>), so the
/// numbers are identical across standard libraries.
class RandomStream {
 public:
  /// The stream `name` (e.g. "lidar", "imu.gyro") of the run seeded with `seed`.
  RandomStream(std::uint64_t seed, std::string_view name);

  /// The next 64 random bits.
  std::uint64_t NextU64();
  /// Uniform in [0, 1), 53 bits.
  double Uniform();
  /// Standard normal (ziggurat method).
  double Gaussian();
  /// Exponential with `rate` (> 0, per unit), by inversion.
  double Exponential(double rate);

 private:
  std::array<std::uint64_t, 4> state_{};
};

/// 64-bit FNV-1a hash of `text`; stable across platforms (used to name streams).
std::uint64_t Fnv1a64(std::string_view text);

}  // namespace slamrig
