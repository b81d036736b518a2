#include "slam/pf/resampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>

namespace slamrig::slam {
namespace {

std::vector<double> RandomWeights(RandomEngine& rng, int n) {
  std::vector<double> log_w(static_cast<std::size_t>(n));
  for (double& l : log_w) l = 3.0 * StandardNormal(rng);
  return SoftmaxWeights(log_w);
}

TEST(ResamplingTest, SoftmaxSumsToOneAndSurvivesHugeAndInfiniteLogs) {
  RandomEngine rng(1);
  for (int trial = 0; trial < 1000; ++trial) {
    const std::vector<double> w = RandomWeights(rng, 1 + trial % 50);
    EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-12);
  }
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> w = SoftmaxWeights(std::vector<double>{1e6, 1e6 - std::log(3.0), -inf});
  EXPECT_NEAR(w[0], 0.75, 1e-9);  // 1e6 - log(3) keeps only ~10 digits of log(3)
  EXPECT_NEAR(w[1], 0.25, 1e-9);
  EXPECT_EQ(w[2], 0.0);
  const std::vector<double> none = SoftmaxWeights(std::vector<double>{-inf, -inf});
  EXPECT_EQ(none[0], 0.5);
}

TEST(ResamplingTest, EffectiveSampleSize) {
  EXPECT_NEAR(EffectiveSampleSize(std::vector<double>(10, 0.1)), 10.0, 1e-9);
  EXPECT_NEAR(EffectiveSampleSize(std::vector<double>{1.0, 0.0, 0.0}), 1.0, 1e-12);
  EXPECT_NEAR(EffectiveSampleSize(std::vector<double>{0.5, 0.5, 0.0}), 2.0, 1e-12);
}

// Counts stay within 1 (systematic) or 2 (stratified) of N w, the particle count is kept, and
// indices come out ascending.
TEST(ResamplingTest, KeepsCountAndDrawsEachParticleInProportion) {
  RandomEngine rng(9);
  for (const ResamplingScheme scheme :
       {ResamplingScheme::kSystematic, ResamplingScheme::kStratified}) {
    const double bound = scheme == ResamplingScheme::kSystematic ? 1.0 : 2.0;
    for (int trial = 0; trial < 2000; ++trial) {
      const int n = 1 + trial % 200;
      const std::vector<double> w = RandomWeights(rng, n);
      const std::vector<int> idx = Resample(w, scheme, rng);
      ASSERT_EQ(idx.size(), static_cast<std::size_t>(n));
      ASSERT_TRUE(std::is_sorted(idx.begin(), idx.end()));
      std::vector<int> count(static_cast<std::size_t>(n), 0);
      for (const int i : idx) ++count[static_cast<std::size_t>(i)];
      for (int j = 0; j < n; ++j) {
        ASSERT_LT(std::abs(count[static_cast<std::size_t>(j)] - n * w[static_cast<std::size_t>(j)]),
                  bound + 1e-9)
            << "n=" << n << " j=" << j;
      }
    }
  }
}

TEST(ResamplingTest, UniformWeightsKeepEveryParticleOnceWithSystematic) {
  RandomEngine rng(2);
  const std::vector<int> idx =
      Resample(std::vector<double>(7, 1.0 / 7), ResamplingScheme::kSystematic, rng);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(idx[static_cast<std::size_t>(i)], i);
}

TEST(ResamplingTest, StratifiedIsUnbiased) {
  RandomEngine rng(4);
  const std::vector<double> w = {0.05, 0.3, 0.15, 0.5};
  std::vector<double> total(4, 0.0);
  const int trials = 20000;
  for (int t = 0; t < trials; ++t) {
    for (const int i : Resample(w, ResamplingScheme::kStratified, rng))
      total[static_cast<std::size_t>(i)] += 1.0;
  }
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(total[j] / (4.0 * trials), w[j], 0.005);
}

}  // namespace
}  // namespace slamrig::slam
