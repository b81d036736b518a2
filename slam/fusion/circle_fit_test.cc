#include "slam/fusion/circle_fit.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

namespace slamrig::slam {
namespace {

// Points on a quarter arc (what a lidar sees of a pillar) with 5 mm noise: the centre and radius
// come back within a few centimetres (a short arc leaves the radius weakly determined), and the
// reported centre covariance matches the actual errors (mean NEES near 2 over the trials).
TEST(CircleFitTest, RecoversAKnownCircleFromNoisyArcPoints) {
  const Eigen::Vector2d center(3.0, -1.5);
  const double radius = 0.2;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.005);
  double nees_sum = 0.0;
  const int trials = 200;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<Eigen::Vector2d> points;
    const double start = 0.031 * trial;
    for (int i = 0; i < 30; ++i) {
      const double a = start + 1.6 * i / 29.0;
      const double rr = radius + noise(rng);
      points.push_back(center + rr * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    const std::optional<CircleFit> fit = FitCircle(points);
    ASSERT_TRUE(fit.has_value());
    EXPECT_LT((fit->center - center).norm(), 0.05) << trial;
    EXPECT_NEAR(fit->radius_m, radius, 0.05) << trial;
    EXPECT_NEAR(fit->rms_m, 0.005, 0.003) << trial;
    const Eigen::Vector2d e = fit->center - center;
    nees_sum += e.dot(fit->center_covariance.inverse() * e);
  }
  EXPECT_GT(nees_sum / trials, 1.5);
  EXPECT_LT(nees_sum / trials, 3.0);
}

TEST(CircleFitTest, CollinearOrTooFewPointsHaveNoCircle) {
  EXPECT_FALSE(FitCircle({{0, 0}, {1, 1}}).has_value());
  EXPECT_FALSE(FitCircle({{0, 0}, {1, 1}, {2, 2}, {3, 3}}).has_value());
}

}  // namespace
}  // namespace slamrig::slam
