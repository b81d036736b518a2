#include "sim/encoder_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace slamrig::sim {
namespace {

TEST(EncoderModelTest, CountsWholeTicksOfEachWheel) {
  EncoderOptions o;
  o.ticks_per_revolution = 360;
  EncoderModel encoders(o, 2, 2, 1, 0.1);
  const double rev = 2.0 * std::numbers::pi;
  // Right wheels one turn, left wheels half a turn backwards.
  const WheelTicks t = encoders.Measure(Time::FromSeconds(0.025),
                                        std::vector<double>{rev, rev, -0.5 * rev, -0.5 * rev});
  EXPECT_EQ(t.right_ticks, (std::vector<std::int32_t>{360, 360}));
  EXPECT_EQ(t.left_ticks, (std::vector<std::int32_t>{-180, -180}));
  EXPECT_EQ(t.time, Time::FromSeconds(0.025));
}

TEST(EncoderModelTest, QuantizationNeverAccumulates) {
  EncoderOptions o;
  o.ticks_per_revolution = 100;
  EncoderModel encoders(o, 1, 1, 7, 0.1);
  const double tick = 2.0 * std::numbers::pi / 100.0;
  int right_total = 0;
  for (int i = 1; i <= 1000; ++i) {
    const double angle = i * 0.37 * tick;  // less than a tick per sample
    const WheelTicks t = encoders.Measure(Time{}, std::vector<double>{angle, 0.0});
    EXPECT_GE(t.right_ticks[0], 0);
    EXPECT_LE(t.right_ticks[0], 1);
    right_total += t.right_ticks[0];
  }
  EXPECT_NEAR(right_total, 370, 1);
}

// One wheel per side turning steadily, a slip draw held for exactly 10 samples (5 m of a 0.5 m
// wheel at 1 rad per sample): the counted rotation of each held stretch, divided by the true
// one, is 1 + s; over many stretches s has the configured spread, the shared part is equal on
// both sides, and the same seed gives the same ticks.
std::vector<double> StretchSlips(const EncoderOptions& o, std::uint64_t seed, bool right) {
  EncoderModel encoders(o, 1, 1, seed, 0.5);
  const double ticks_per_rad = o.ticks_per_revolution / (2.0 * std::numbers::pi);
  std::vector<double> slips;
  std::int64_t stretch = 0;
  for (int i = 1; i <= 20000; ++i) {
    const WheelTicks t = encoders.Measure(Time{}, std::vector<double>{1.0 * i, 1.0 * i});
    stretch += right ? t.right_ticks[0] : t.left_ticks[0];
    if (i % 10 == 0) {
      slips.push_back(static_cast<double>(stretch) / (10.0 * ticks_per_rad) - 1.0);
      stretch = 0;
    }
  }
  return slips;
}

double Mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (const double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

double StdDev(const std::vector<double>& v) {
  const double mean = Mean(v);
  double sum = 0.0;
  for (const double x : v) sum += (x - mean) * (x - mean);
  return std::sqrt(sum / static_cast<double>(v.size() - 1));
}

TEST(EncoderModelTest, SlipHasItsSpreadAndIsSeeded) {
  EncoderOptions o;
  o.ticks_per_revolution = 100000;  // quantisation far below the slip
  o.slip_stddev = 0.03;
  o.slip_length_m = 5.0;
  const std::vector<double> right = StretchSlips(o, 5, true), left = StretchSlips(o, 5, false);
  ASSERT_EQ(right.size(), 2000u);
  // 2000 draws: the sample stddev is within ~3 % of the true one (1 sigma), the mean within
  // 0.03 / sqrt(2000) = 0.0007.
  EXPECT_NEAR(StdDev(right), 0.03, 0.003);
  EXPECT_NEAR(StdDev(left), 0.03, 0.003);
  EXPECT_NEAR(Mean(right), 0.0, 0.003);
  EXPECT_EQ(StretchSlips(o, 5, true), right);
  EXPECT_NE(StretchSlips(o, 6, true), right);
  // Independent sides: their difference has sqrt(2) times the spread.
  std::vector<double> difference;
  for (std::size_t i = 0; i < right.size(); ++i) difference.push_back(right[i] - left[i]);
  EXPECT_NEAR(StdDev(difference), 0.03 * std::sqrt(2.0), 0.005);

  // Shared slip only: both sides slip alike.
  o.slip_stddev = 0.0;
  o.slip_common_stddev = 0.05;
  const std::vector<double> shared_right = StretchSlips(o, 5, true);
  const std::vector<double> shared_left = StretchSlips(o, 5, false);
  EXPECT_NEAR(StdDev(shared_right), 0.05, 0.005);
  for (std::size_t i = 0; i < shared_right.size(); ++i) {
    ASSERT_NEAR(shared_right[i], shared_left[i], 1e-4) << i;
  }
}

TEST(EncoderModelTest, NoSlipCountsTheTrueRotation) {
  EncoderOptions o;
  o.ticks_per_revolution = 100000;
  const std::vector<double> slips = StretchSlips(o, 5, true);
  for (const double s : slips) ASSERT_NEAR(s, 0.0, 2e-5);
}

}  // namespace
}  // namespace slamrig::sim
