#include "slam/types/random_stream.h"

#include <cmath>

#include "slam/types/check.h"

namespace slamrig {
namespace {

std::uint64_t SplitMix64(std::uint64_t* x) {
  std::uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t RotateLeft(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

// Layer edges of the 128-layer normal ziggurat: x[0] = v / f(r) (the base layer with its tail),
// x[1] = r, x[128] = 0, each layer of area v; ratio[i] = x[i + 1] / x[i].
struct ZigguratTables {
  static constexpr int kLayers = 128;
  static constexpr double kR = 3.442619855899;
  static constexpr double kV = 9.91256303526217e-3;
  std::array<double, kLayers + 1> x{};
  std::array<double, kLayers> ratio{};

  ZigguratTables() {
    double f = std::exp(-0.5 * kR * kR);
    x[0] = kV / f;
    x[1] = kR;
    x[kLayers] = 0.0;
    for (int i = 2; i < kLayers; ++i) {
      x[i] = std::sqrt(-2.0 * std::log(kV / x[i - 1] + f));
      f = std::exp(-0.5 * x[i] * x[i]);
    }
    for (int i = 0; i < kLayers; ++i) ratio[i] = x[i + 1] / x[i];
  }
};

const ZigguratTables& Tables() {
  static const ZigguratTables tables;
  return tables;
}

}  // namespace

std::uint64_t Fnv1a64(std::string_view text) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

RandomStream::RandomStream(std::uint64_t seed, std::string_view name) {
  // Mix the seed and the name through SplitMix64 so that nearby seeds and similar names still
  // give unrelated states (the seeding Vigna recommends for xoshiro).
  std::uint64_t x = seed ^ RotateLeft(Fnv1a64(name), 17);
  x = SplitMix64(&x) ^ Fnv1a64(name);
  for (auto& word : state_) word = SplitMix64(&x);
}

std::uint64_t RandomStream::NextU64() {
  const std::uint64_t result = RotateLeft(state_[1] * 5, 7) * 9;
  const std::uint64_t t = state_[1] << 17;
  state_[2] ^= state_[0];
  state_[3] ^= state_[1];
  state_[1] ^= state_[2];
  state_[0] ^= state_[3];
  state_[2] ^= t;
  state_[3] = RotateLeft(state_[3], 45);
  return result;
}

double RandomStream::Uniform() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }

double RandomStream::Gaussian() {
  // Ziggurat method (Marsaglia and Tsang, "The Ziggurat Method for Generating Random Variables",
  // J. Stat. Softw. 5(8), 2000) with 128 layers, drawing the layer and the abscissa from separate
  // bits as Doornik recommends ("An Improved Ziggurat Method to Generate Normal Random Samples",
  // 2005). Almost every sample costs one 64-bit draw and a multiply.
  const ZigguratTables& z = Tables();
  for (;;) {
    const std::uint64_t bits = NextU64();
    const double u = 2.0 * (static_cast<double>(bits >> 11) * 0x1.0p-53) - 1.0;
    const std::size_t i = bits & 0x7f;
    if (std::abs(u) < z.ratio[i]) return u * z.x[i];
    if (i == 0) {
      // The base layer's tail beyond r (Marsaglia, 1964).
      double x = 0.0, y = 0.0;
      do {
        x = std::log1p(-Uniform()) / ZigguratTables::kR;
        y = std::log1p(-Uniform());
      } while (-2.0 * y < x * x);
      return u < 0.0 ? x - ZigguratTables::kR : ZigguratTables::kR - x;
    }
    // The wedge between layer i and i + 1.
    const double x = u * z.x[i];
    const double f0 = std::exp(-0.5 * (z.x[i] * z.x[i] - x * x));
    const double f1 = std::exp(-0.5 * (z.x[i + 1] * z.x[i + 1] - x * x));
    if (f1 + Uniform() * (f0 - f1) < 1.0) return x;
  }
}

double RandomStream::Exponential(double rate) {
  SLAMRIG_DCHECK(rate > 0.0, "exponential rate must be positive");
  return -std::log1p(-Uniform()) / rate;
}

}  // namespace slamrig
