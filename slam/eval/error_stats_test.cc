#include "slam/eval/error_stats.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

TEST(ErrorStatsTest, MatchesHandComputedValues) {
  const ErrorStats s = ErrorStats::Of({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(s.std_dev, std::sqrt(30.0 / 4.0 - 6.25));
  EXPECT_DOUBLE_EQ(ErrorStats::Of({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_EQ(ErrorStats::Of({}).count, 0);
}

}  // namespace
}  // namespace slamrig::slam
