#include "sim/driver.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::sim {
namespace {

TEST(DriverTest, PlaysAScheduleLapAfterLap) {
  DriveOptions options;
  options.mode = DriveMode::kSchedule;
  options.schedule = {{1.0, 0.5, 0.0}, {2.0, 0.0, 0.3}};
  options.laps = 2;
  Driver driver(options);
  EXPECT_EQ(driver.Update(Time::FromSeconds(10.0), Pose2()).v_m_s, 0.5);  // the clock starts here
  EXPECT_EQ(driver.Update(Time::FromSeconds(11.5), Pose2()).omega_rad_s, 0.3);
  EXPECT_EQ(driver.Update(Time::FromSeconds(13.2), Pose2()).v_m_s, 0.5);  // second lap
  EXPECT_FALSE(driver.finished());
  EXPECT_EQ(driver.Update(Time::FromSeconds(16.1), Pose2()).omega_rad_s, 0.0);
  EXPECT_TRUE(driver.finished());
}

TEST(DriverTest, PurePursuitDrivesASquareTwiceAndStops) {
  DriveOptions options;
  options.mode = DriveMode::kWaypoints;
  options.waypoints_m = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
  options.laps = 2;
  options.speed_m_s = 0.5;
  options.lookahead_m = 0.5;
  Driver driver(options);
  // A perfect unicycle.
  double x = 0.0, y = 0.0, yaw = 0.0, max_off_path = 0.0;
  const double dt = 0.02;
  int steps = 0;
  for (; steps < 20000 && !driver.finished(); ++steps) {
    const VelocityCommand c = driver.Update(Time::FromSeconds(steps * dt), Pose2(x, y, yaw));
    x += c.v_m_s * std::cos(yaw) * dt;
    y += c.v_m_s * std::sin(yaw) * dt;
    yaw += c.omega_rad_s * dt;
    const double off = std::min({std::abs(y), std::abs(x - 4), std::abs(y - 4), std::abs(x)});
    max_off_path = std::max(max_off_path, off);
  }
  EXPECT_TRUE(driver.finished());
  EXPECT_EQ(driver.laps_completed(), 2);
  EXPECT_NEAR(driver.progress_m(), 32.0, 1e-9);
  EXPECT_LT(std::hypot(x, y), 0.3);
  EXPECT_LT(max_off_path, 0.3);
  EXPECT_NEAR(steps * dt, 32.0 / 0.5, 12.0);
}

// A square with a dead-end spur: (4, 0) -> (4, -3) and back. With dead_end_reach_m the robot
// drives to the spur's end before it turns, and finishes the lap.
TEST(DriverTest, DrivesIntoADeadEndAndBackOut) {
  DriveOptions options;
  options.mode = DriveMode::kWaypoints;
  options.waypoints_m = {{0, 0}, {4, 0}, {4, -3}, {4, 0}, {4, 4}, {0, 4}};
  options.speed_m_s = 0.5;
  options.lookahead_m = 0.5;
  options.turn_in_place_rad = 0.5;
  options.dead_end_reach_m = 0.25;
  Driver driver(options);
  double x = 0.0, y = 0.0, yaw = 0.0, lowest_y = 0.0;
  const double dt = 0.02;
  int steps = 0;
  for (; steps < 20000 && !driver.finished(); ++steps) {
    const VelocityCommand c = driver.Update(Time::FromSeconds(steps * dt), Pose2(x, y, yaw));
    x += c.v_m_s * std::cos(yaw) * dt;
    y += c.v_m_s * std::sin(yaw) * dt;
    yaw += c.omega_rad_s * dt;
    lowest_y = std::min(lowest_y, y);
  }
  EXPECT_TRUE(driver.finished());
  EXPECT_LT(lowest_y, -2.75);  // reached the dead end's last 0.25 m
  EXPECT_LT(std::hypot(x, y), 0.3);
  EXPECT_LT(steps * dt, 22.0 / 0.5 + 30.0);
}

TEST(DriverTest, ValidateNamesTheField) {
  DriveOptions options;
  options.mode = DriveMode::kWaypoints;
  options.waypoints_m = {{0, 0}};
  options.laps = 0;
  const auto errors = options.Validate();
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0], "laps = 0; must be >= 1");
  EXPECT_EQ(errors[1], "waypoints_m has 1 points; pure pursuit needs at least 2");
}

}  // namespace
}  // namespace slamrig::sim
