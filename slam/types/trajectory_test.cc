#include "slam/types/trajectory.h"

#include <gtest/gtest.h>

#include <numbers>

namespace slamrig {
namespace {

TEST(TrajectoryTest, InterpolatesPositionAndShortestArcHeading) {
  Trajectory t;
  t.Append(Time::FromSeconds(0.0), Pose2(0.0, 0.0, 3.0));
  t.Append(Time::FromSeconds(1.0), Pose2(2.0, 4.0, -3.0));  // 0.283 rad across the +-pi seam
  const auto mid = t.Interpolate(Time::FromSeconds(0.5));
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->x(), 1.0, 1e-12);
  EXPECT_NEAR(mid->y(), 2.0, 1e-12);
  EXPECT_NEAR(std::abs(mid->theta()), std::numbers::pi, 1e-9);
  EXPECT_FALSE(t.Interpolate(Time::FromSeconds(1.5)).has_value());
  EXPECT_FALSE(t.Interpolate(Time::FromSeconds(-0.1)).has_value());
  EXPECT_NEAR(t.PathLength(), std::sqrt(20.0), 1e-12);
}

TEST(TrajectoryTest, ExactSampleTimesReturnTheSample) {
  Trajectory t;
  t.Append(Time::FromSeconds(1.0), Pose2(1.0, 0.0, 0.1));
  t.Append(Time::FromSeconds(2.0), Pose2(5.0, 0.0, 0.2));
  EXPECT_EQ(*t.Interpolate(Time::FromSeconds(1.0)), Pose2(1.0, 0.0, 0.1));
  EXPECT_EQ(*t.Interpolate(Time::FromSeconds(2.0)), Pose2(5.0, 0.0, 0.2));
}

TEST(TrajectoryDeathTest, RejectsTimeGoingBackwards) {
  Trajectory t;
  t.Append(Time::FromSeconds(2.0), Pose2());
  EXPECT_DEATH(t.Append(Time::FromSeconds(1.0), Pose2()), "non-decreasing");
}

}  // namespace
}  // namespace slamrig
