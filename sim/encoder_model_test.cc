#include "sim/encoder_model.h"

#include <gtest/gtest.h>

#include <numbers>

namespace slamrig::sim {
namespace {

TEST(EncoderModelTest, CountsWholeTicksOfEachWheel) {
  EncoderOptions o;
  o.ticks_per_revolution = 360;
  EncoderModel encoders(o, 2, 2, 1);
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
  EncoderModel encoders(o, 1, 1, 7);
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

}  // namespace
}  // namespace slamrig::sim
