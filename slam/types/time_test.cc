#include "slam/types/time.h"

#include <gtest/gtest.h>

#include <random>

namespace slamrig {
namespace {

TEST(TimeTest, SecondsRoundTripWithinHalfNanosecond) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> seconds(-1e4, 1e4);
  for (int i = 0; i < 10000; ++i) {
    const double s = seconds(rng);
    ASSERT_NEAR(Time::FromSeconds(s).seconds(), s, 1e-9);
  }
}

TEST(TimeTest, DifferencesAreExact) {
  const Time a = Time::FromNanoseconds(1'298'445'274'541'885'000);
  const Time b = Time::FromNanoseconds(1'298'445'274'566'885'000);
  EXPECT_DOUBLE_EQ(SecondsBetween(b, a), 0.025);
  EXPECT_LT(a, b);
  EXPECT_EQ(AddSeconds(a, 0.025), b);
}

}  // namespace
}  // namespace slamrig
