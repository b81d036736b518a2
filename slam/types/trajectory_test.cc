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

// A real log's stamps may go backwards: each pose keeps its own stamp, in the order appended,
// and a "pose at a time" is no longer defined.
TEST(TrajectoryTest, KeepsStampsThatGoBackwardsAndCountsThem) {
  Trajectory t;
  t.Append(Time::FromSeconds(2.0), Pose2(1.0, 0.0, 0.0));
  EXPECT_TRUE(t.time_ordered());
  t.Append(Time::FromSeconds(1.0), Pose2(2.0, 0.0, 0.0));
  t.Append(Time::FromSeconds(3.0), Pose2(3.0, 0.0, 0.0));
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[1].time, Time::FromSeconds(1.0));
  EXPECT_EQ(t[1].pose, Pose2(2.0, 0.0, 0.0));
  EXPECT_FALSE(t.time_ordered());
  EXPECT_EQ(t.out_of_order(), 1);
  EXPECT_FALSE(t.Interpolate(Time::FromSeconds(2.5)).has_value());
  EXPECT_EQ(Trajectory(t.poses()).out_of_order(), 1);
}

}  // namespace
}  // namespace slamrig
