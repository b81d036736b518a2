// Stratified and systematic resampling (Wang, ECE276A report, Sec. II-C, the stratified algorithm;
// Douc, Cappe, Moulines, "Comparison of Resampling Schemes for Particle Filtering", ISPA 2005,
// Sec. 2.2-2.3) and the effective sample size of Zafari's report, Eq. 6.
#include "slam/pf/resampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/types/check.h"

namespace slamrig::slam {

double EffectiveSampleSize(std::span<const double> weights) {
  double sum_sq = 0.0;
  for (const double w : weights) sum_sq += w * w;
  return sum_sq > 0.0 ? 1.0 / sum_sq : 0.0;
}

std::vector<double> SoftmaxWeights(std::span<const double> log_weights) {
  double max_log = -std::numeric_limits<double>::infinity();
  for (const double l : log_weights) {
    if (std::isfinite(l)) max_log = std::max(max_log, l);
  }
  std::vector<double> weights(log_weights.size(), 0.0);
  if (!std::isfinite(max_log)) {
    std::fill(weights.begin(), weights.end(), 1.0 / static_cast<double>(weights.size()));
    return weights;
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < log_weights.size(); ++i) {
    if (std::isfinite(log_weights[i])) weights[i] = std::exp(log_weights[i] - max_log);
    sum += weights[i];
  }
  for (double& w : weights) w /= sum;
  return weights;
}

std::vector<int> Resample(std::span<const double> weights, ResamplingScheme scheme,
                          RandomEngine& rng) {
  const std::size_t n = weights.size();
  SLAMRIG_CHECK(n > 0, "cannot resample zero particles");
  std::vector<int> indices;
  indices.reserve(n);
  const double shared = Uniform01(rng);
  std::size_t j = 0;
  double cumulative = weights[0];
  for (std::size_t k = 0; k < n; ++k) {
    const double u =
        scheme == ResamplingScheme::kSystematic ? shared : (k == 0 ? shared : Uniform01(rng));
    const double beta = (static_cast<double>(k) + u) / static_cast<double>(n);
    // Rounding can leave the last cumulative sum a hair under 1: never run past the end.
    while (beta > cumulative && j + 1 < n) cumulative += weights[++j];
    indices.push_back(static_cast<int>(j));
  }
  return indices;
}

}  // namespace slamrig::slam
