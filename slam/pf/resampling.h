#pragma once

#include <span>
#include <vector>

#include "slam/odometry/gaussian.h"

namespace slamrig::slam {

/// How particles are redrawn when the effective sample size falls under the threshold.
enum class ResamplingScheme {
  /// One uniform draw per stratum [k/N, (k+1)/N) (the ECE276A reports' choice; Wang Sec. II-C).
  kStratified,
  /// One uniform draw shared by all strata, u_k = (k + U) / N: lower variance, cheaper.
  kSystematic,
};

/// Effective sample size 1 / sum(w^2) of normalised weights (Zafari, ECE276A report, Eq. 6).
double EffectiveSampleSize(std::span<const double> weights);

/// Turns log-weights into normalised weights (softmax, shifted by the maximum for stability;
/// Wang, Eq. 7). Non-finite log-weights get weight 0; if none is finite the weights are uniform.
std::vector<double> SoftmaxWeights(std::span<const double> log_weights);

/// Indices of the particles to keep, ascending, `weights.size()` of them; weights must be
/// normalised. Particle j is drawn c_j times with |c_j - N w_j| < 1 (systematic) or < 2
/// (stratified): a particle of weight >= 2/N always survives.
std::vector<int> Resample(std::span<const double> weights, ResamplingScheme scheme,
                          RandomEngine& rng);

}  // namespace slamrig::slam
