#include "slam/matching/adaptive_field_sigma.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace slamrig::slam {
namespace {

// A 4 m x 4 m grid at 0.05 m with one straight wall: the row of cells whose centres lie on y
// = 2.025.
OccupancyGrid GridWithAWall() {
  OccupancyGridOptions options;
  options.resolution_m = 0.05;
  options.grow_margin_m = 0.0;
  OccupancyGrid grid(options, Eigen::Vector2d(0, 0), 80, 80);
  for (int x = 0; x < 80; ++x) grid.Set({x, 40}, 2.0f);
  return grid;
}

constexpr double kWallY = 2.025;

// `n` points spread along the wall (x in [1, 3]), each `offset(i)` above it, in the frame of a
// robot at (0.5, 1) facing +x.
template <typename Offset>
std::vector<Eigen::Vector2d> PointsOffTheWall(int n, Offset offset, Pose2* pose) {
  *pose = Pose2(0.5, 1.0, 0.0);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d world(1.0 + 2.0 * i / n, kWallY + offset(i));
    points.push_back(pose->Inverse() * world);
  }
  return points;
}

TEST(AdaptiveFieldSigmaTest, DistanceInvertsTheFieldsScore) {
  for (const double sigma : {0.03, 0.05, 0.08, 0.12}) {
    LikelihoodFieldOptions options;
    options.sigma_m = sigma;
    const LikelihoodField field(options);
    for (double d = 0.0; d < options.cutoff_sigmas * sigma; d += 0.001) {
      EXPECT_NEAR(field.Distance(field.Score(d)), d, 1e-6) << sigma << " " << d;
    }
    EXPECT_TRUE(std::isinf(field.Distance(0.0)));
    EXPECT_TRUE(std::isinf(field.Distance(-1.0)));
  }
}

TEST(AdaptiveFieldSigmaTest, SetSigmaRecomputesAFollowedFieldAsANewFieldWould) {
  OccupancyGrid grid = GridWithAWall();
  grid.Set({10, 10}, 2.0f);
  LikelihoodFieldOptions options;
  options.sigma_m = 0.08;
  LikelihoodField followed(options);
  followed.Follow(grid);
  followed.SetSigma(0.05);
  EXPECT_EQ(followed.sigma_m(), 0.05);
  grid.Set({60, 20}, 2.0f);  // a change after the new sigma, followed as usual
  followed.Follow(grid);
  options.sigma_m = 0.05;
  LikelihoodField fresh(options);
  fresh.Follow(grid);
  const GridView a = followed.view(), b = fresh.view();
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  EXPECT_EQ(std::memcmp(a.values, b.values, sizeof(float) * a.width * a.height), 0);
}

// The median read off the field follows the points' median distance from the wall, over sigmas
// and spreads. It reads high by about a fifth of a cell: the bilinear interpolation between cell
// centres lies below the field's peak, so a point on the wall reads 0.01-0.02 m off it (at
// 0.05 m cells). The sigma's factor is measured on that reading (AdaptiveSigmaOptions).
TEST(AdaptiveFieldSigmaTest, MedianWallDistanceMeasuresHowFarThePointsLieOffTheWall) {
  OccupancyGrid grid = GridWithAWall();
  std::mt19937 rng(3);
  for (const double sigma : {0.05, 0.08, 0.12}) {
    LikelihoodFieldOptions field_options;
    field_options.sigma_m = sigma;
    LikelihoodField field(field_options);
    field.Follow(grid);
    AdaptiveSigmaOptions options;
    const AdaptiveFieldSigma adaptive(options);
    double previous = 0.0;
    for (const double spread : {0.01, 0.02, 0.04, 0.06}) {
      std::normal_distribution<double> noise(0.0, spread);
      std::vector<double> offsets;
      for (int i = 0; i < 200; ++i) offsets.push_back(noise(rng));
      Pose2 pose;
      const auto points = PointsOffTheWall(
          200, [&](int i) { return offsets[i]; }, &pose);
      std::vector<double> near;
      for (double o : offsets) {
        if (std::abs(o) <= options.window_m) near.push_back(std::abs(o));
      }
      std::nth_element(near.begin(), near.begin() + near.size() / 2, near.end());
      const double expected = near[near.size() / 2];
      const std::optional<double> median = adaptive.MedianWallDistance(field, points, pose);
      ASSERT_TRUE(median.has_value());
      EXPECT_GT(*median, expected) << sigma << " " << spread;
      EXPECT_LT(*median, expected + 0.015) << sigma << " " << spread;
      EXPECT_GT(*median, previous) << sigma << " " << spread;
      previous = *median;
    }
  }
}

TEST(AdaptiveFieldSigmaTest, PointsFarFromEveryWallAreNotCounted) {
  OccupancyGrid grid = GridWithAWall();
  LikelihoodFieldOptions field_options;
  field_options.sigma_m = 0.08;
  LikelihoodField field(field_options);
  field.Follow(grid);
  AdaptiveSigmaOptions options;
  options.min_points = 20;
  const AdaptiveFieldSigma adaptive(options);
  Pose2 pose;
  // 30 points near the wall and 100 in open space: the median is the near points' alone.
  const auto near = PointsOffTheWall(
      30, [](int i) { return 0.002 * i - 0.03; }, &pose);
  const auto open = PointsOffTheWall(
      100, [](int) { return -0.5; }, &pose);
  auto points = near;
  points.insert(points.end(), open.begin(), open.end());
  const std::optional<double> median = adaptive.MedianWallDistance(field, points, pose);
  ASSERT_TRUE(median.has_value());
  EXPECT_EQ(*median, adaptive.MedianWallDistance(field, near, pose).value());
  // Too few near a wall: nothing to say.
  const auto few = PointsOffTheWall(
      19, [](int) { return 0.01; }, &pose);
  EXPECT_FALSE(adaptive.MedianWallDistance(field, few, pose).has_value());
}

TEST(AdaptiveFieldSigmaTest, TheSigmaFollowsTheSmoothedMedianWithinItsBounds) {
  AdaptiveSigmaOptions options;
  options.enabled = true;
  options.residual_factor = 2.0;
  options.min_m = 0.05;
  options.max_m = 0.12;
  options.warmup_updates = 10;
  options.rate = 0.1;
  options.change_ratio = 0.1;
  AdaptiveFieldSigma adaptive(options);
  double sigma = 0.08;  // the field's, moved where Observe says
  auto observe = [&](AdaptiveFieldSigma& a, double median) {
    const std::optional<double> moved = a.Observe(median, sigma);
    if (moved) sigma = *moved;
    return moved.has_value();
  };
  // Warm-up: a median implying 0.06 moves nothing for 10 updates.
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(observe(adaptive, 0.03));
  EXPECT_EQ(sigma, 0.08);
  EXPECT_TRUE(observe(adaptive, 0.03));
  EXPECT_NEAR(sigma, 0.06, 1e-12);
  // Within change_ratio of the sigma in use: no move.
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(observe(adaptive, 0.0315));
  EXPECT_NEAR(adaptive.median_m(), 0.0315, 1e-4);
  // Blurred walls raise it to its bound and no further; sharp ones lower it to the other.
  for (int i = 0; i < 200; ++i) observe(adaptive, 0.2);
  EXPECT_EQ(sigma, 0.12);
  for (int i = 0; i < 200; ++i) observe(adaptive, 0.001);
  EXPECT_EQ(sigma, 0.05);
  EXPECT_GE(adaptive.moves(), 3);
  // Off: the sigma stays.
  options.enabled = false;
  AdaptiveFieldSigma off(options);
  sigma = 0.08;
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(observe(off, 0.01));
  EXPECT_EQ(sigma, 0.08);
}

}  // namespace
}  // namespace slamrig::slam
