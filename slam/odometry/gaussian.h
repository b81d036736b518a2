#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace slamrig::slam {

/// The random engine every slamrig estimator uses: its output sequence is fixed by the standard,
/// so together with the samplers below results are identical across compilers and libraries
/// (std::normal_distribution is not).
using RandomEngine = std::mt19937_64;

/// Uniform double in [0, 1) with 53 random bits.
inline double Uniform01(RandomEngine& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// Standard normal sample (Box-Muller; one of the pair is discarded to keep the stream stateless).
inline double StandardNormal(RandomEngine& rng) {
  const double u1 = 1.0 - Uniform01(rng);  // (0, 1]: log is finite
  const double u2 = Uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// Three independent Uniform01 samples, the last component drawn first (see StandardNormal3).
inline Eigen::Vector3d Uniform3(RandomEngine& rng) {
  const double z = Uniform01(rng);
  const double y = Uniform01(rng);
  const double x = Uniform01(rng);
  return {x, y, z};
}

/// Three independent standard normal samples. The last component is drawn first: three draws as
/// the arguments of one call come in an order the compiler chooses (gcc: last first), so callers
/// take them from here, in the order that made the results recorded so far.
inline Eigen::Vector3d StandardNormal3(RandomEngine& rng) {
  const double z = StandardNormal(rng);
  const double y = StandardNormal(rng);
  const double x = StandardNormal(rng);
  return {x, y, z};
}

}  // namespace slamrig::slam
