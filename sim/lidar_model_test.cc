#include "sim/lidar_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace slamrig::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(LidarModelTest, DefaultsAreAHokuyoUtm30lx) {
  const LidarOptions o;
  EXPECT_NEAR(o.angle_increment_rad(), 0.25 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_NEAR(o.angle_min_rad(), -0.75 * std::numbers::pi, 1e-15);
  EXPECT_NEAR(o.time_increment_s(), 1.0 / (40.0 * 1440.0), 1e-18);
  EXPECT_TRUE(o.Validate().empty());
}

TEST(LidarModelTest, NoReturnIsExactlyMaxRangeAndHitsAreRounded) {
  LidarOptions o;
  o.range_noise_stddev_m = 0.0;
  o.p_short = o.p_max = o.p_random = 0.0;
  LidarModel model(o, 1);
  std::vector<double> truth(static_cast<std::size_t>(o.num_beams), kInf);
  truth[0] = 1.23449;
  truth[1] = 0.05;  // closer than range_min: reported as measured, invalid by the contract
  truth[2] = 30.0;  // at max range: no return
  const LaserScan scan = model.MakeScan(Time::FromSeconds(2.0), truth);
  EXPECT_FLOAT_EQ(scan.ranges_m[0], 1.234f);
  EXPECT_FALSE(scan.IsHit(1));
  EXPECT_FALSE(scan.IsHit(2));
  EXPECT_FALSE(scan.IsHit(3));
  EXPECT_EQ(scan.ranges_m[3], 30.0f);
  EXPECT_TRUE(scan.IsHit(0));
  EXPECT_EQ(scan.time, Time::FromSeconds(2.0));
  EXPECT_NEAR(scan.base_from_laser.x(), 0.133, 1e-12);
}

TEST(LidarModelTest, NoiseAndBeamMixtureHaveTheirRates) {
  LidarOptions o;
  o.range_resolution_m = 0.0;
  o.p_short = 0.05;
  o.p_max = 0.02;
  o.p_random = 0.03;
  LidarModel model(o, 3);
  const std::vector<double> truth(static_cast<std::size_t>(o.num_beams), 10.0);
  int short_returns = 0, max_returns = 0, far_outliers = 0, gaussian = 0;
  double sum2 = 0.0;
  for (int scan = 0; scan < 200; ++scan) {
    for (const float r : model.MakeScan(Time{}, truth).ranges_m) {
      const double error = r - 10.0;
      if (r == 30.0f) {
        ++max_returns;
      } else if (std::abs(error) < 0.06) {
        ++gaussian;
        sum2 += error * error;
      } else if (r < 10.0) {
        ++short_returns;
      } else {
        ++far_outliers;
      }
    }
  }
  const double n = 200.0 * o.num_beams;
  EXPECT_NEAR(std::sqrt(sum2 / gaussian), 0.01, 0.0005);
  EXPECT_NEAR(max_returns / n, 0.02, 0.002);
  // Random readings land anywhere in [0.1, 30]; about a third of them fall short of 10 m.
  EXPECT_NEAR(far_outliers / n, 0.03 * 20.0 / 29.9, 0.003);
  EXPECT_NEAR(short_returns / n, 0.05 + 0.03 * 9.9 / 29.9, 0.004);
}

// Range-proportional noise (an RPLIDAR's "1 % of the range"): the empirical sigma at each range
// is the root sum of squares of the fixed and the proportional part.
TEST(LidarModelTest, RangeProportionalNoiseGrowsWithRange) {
  LidarOptions o;
  o.range_noise_stddev_m = 0.002;
  o.range_noise_fraction = 0.01;
  o.range_resolution_m = 0.0;
  o.p_short = o.p_max = o.p_random = 0.0;
  LidarModel model(o, 3);
  for (const double range : {1.0, 5.0, 20.0}) {
    std::vector<double> truth(static_cast<std::size_t>(o.num_beams), range);
    double sum = 0.0, sum2 = 0.0;
    int n = 0;
    for (int k = 0; k < 10; ++k) {
      const LaserScan scan = model.MakeScan(Time::FromSeconds(k), truth);
      for (const float r : scan.ranges_m) {
        sum += r - range;
        sum2 += (r - range) * (r - range);
        ++n;
      }
    }
    const double expected = std::hypot(0.002, 0.01 * range);
    // 10,810 samples: the sample sigma's standard error is 0.7 %; 4 % is > 5 of them.
    EXPECT_NEAR(std::sqrt(sum2 / n), expected, 0.04 * expected) << range;
    EXPECT_NEAR(sum / n, 0.0, 0.05 * expected) << range;
  }
  o.range_noise_fraction = -0.1;
  ASSERT_EQ(o.Validate().size(), 1u);
  EXPECT_EQ(o.Validate()[0], "range_noise_fraction = -0.1; must be in [0, 1]");
}

TEST(LidarModelTest, SameSeedSameNoiseOtherSeedOtherNoise) {
  const LidarOptions o;
  const std::vector<double> truth(static_cast<std::size_t>(o.num_beams), 5.0);
  LidarModel a(o, 1), b(o, 1), c(o, 2);
  const auto ra = a.MakeScan(Time{}, truth).ranges_m;
  EXPECT_EQ(ra, b.MakeScan(Time{}, truth).ranges_m);
  EXPECT_NE(ra, c.MakeScan(Time{}, truth).ranges_m);
}

}  // namespace
}  // namespace slamrig::sim
