#include "slam/types/format.h"

#include <gtest/gtest.h>

namespace slamrig {
namespace {

TEST(FormatTest, FixedRoundsToTheDigits) {
  EXPECT_EQ(Fixed(0.12345, 3), "0.123");
  EXPECT_EQ(Fixed(-2.5, 0), "-2");  // round half to even, as printf does
  EXPECT_EQ(Fixed(1.0, 2), "1.00");
}

TEST(FormatTest, NumberUsesTheFormat) {
  EXPECT_EQ(Number("%.6g", 1234567.0), "1.23457e+06");
  EXPECT_EQ(Number("%.3f", 0.5), "0.500");
}

}  // namespace
}  // namespace slamrig
