#include "slam/odometry/wheel_odometry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace slamrig::slam {
namespace {

WheelTicks Ticks(double t_s, int right, int left) {
  return WheelTicks{Time::FromSeconds(t_s), {right, right}, {left, left}};
}

WheelOdometryOptions EncodersOnly() {
  WheelOdometryOptions options;
  options.use_gyro = false;
  return options;
}

TEST(WheelOdometryTest, MetresPerTickMatchesTheEce276aRobot) {
  EXPECT_NEAR(DiffDriveParams{}.MetresPerTick(), 0.0022, 2e-5);
}

TEST(WheelOdometryTest, EqualTicksDriveStraight) {
  WheelOdometry odometry(EncodersOnly());
  const double m = DiffDriveParams{}.MetresPerTick();
  OdometryPose last;
  for (int k = 1; k <= 100; ++k) last = odometry.AddTicks(Ticks(0.025 * k, 7, 7));
  EXPECT_EQ(last.time, Time::FromSeconds(2.5));
  EXPECT_NEAR(last.odom_from_base.x(), 700 * m, 1e-12);
  EXPECT_NEAR(last.odom_from_base.y(), 0.0, 1e-12);
  EXPECT_NEAR(last.odom_from_base.theta(), 0.0, 1e-12);
}

TEST(WheelOdometryTest, FrontAndRearWheelsAreAveragedPerSide) {
  WheelOdometry odometry(EncodersOnly());
  const double m = DiffDriveParams{}.MetresPerTick();
  const OdometryPose p = odometry.AddTicks(WheelTicks{Time::FromSeconds(0.1), {4, 6}, {5, 5}});
  EXPECT_NEAR(p.odom_from_base.x(), 5 * m, 1e-12);
  EXPECT_NEAR(p.odom_from_base.theta(), 0.0, 1e-12);
}

TEST(WheelOdometryTest, OppositeTicksSpinInPlace) {
  WheelOdometry odometry(EncodersOnly());
  const DiffDriveParams robot;
  const OdometryPose p = odometry.AddTicks(Ticks(0.025, 10, -10));
  EXPECT_NEAR(p.odom_from_base.x(), 0.0, 1e-12);
  EXPECT_NEAR(p.odom_from_base.y(), 0.0, 1e-12);
  EXPECT_NEAR(p.odom_from_base.theta(), 20 * robot.MetresPerTick() / robot.track_width_m, 1e-12);
}

// Constant tick rates put the robot on a circle; the exact-arc model lands on it to round-off.
TEST(WheelOdometryTest, ConstantCurvatureStaysOnTheCircle) {
  const DiffDriveParams robot;
  const double m = robot.MetresPerTick();
  const int right = 9, left = 5;
  const double step_yaw = (right - left) * m / robot.track_width_m;
  const double step_distance = 0.5 * (right + left) * m;
  const double radius = step_distance / step_yaw;
  WheelOdometry odometry(EncodersOnly());
  for (int k = 1; k <= 500; ++k) {
    const Pose2 p = odometry.AddTicks(Ticks(0.025 * k, right, left)).odom_from_base;
    const double phi = k * step_yaw;
    ASSERT_NEAR(p.x(), radius * std::sin(phi), 1e-9) << k;
    ASSERT_NEAR(p.y(), radius * (1.0 - std::cos(phi)), 1e-9) << k;
    ASSERT_NEAR(NormalizeAngle(p.theta() - phi), 0.0, 1e-9) << k;
  }
}

TEST(WheelOdometryTest, GyroGivesYawFromTheMeanRateTimesTheInterval) {
  WheelOdometry odometry(WheelOdometryOptions{});  // use_gyro by default
  const double omega = 0.3;
  // First ticks record: no interval yet, yaw from the (equal) encoders, counted as a fallback.
  odometry.AddTicks(Ticks(0.0, 0, 0));
  EXPECT_EQ(odometry.gyro_fallbacks(), 1);
  int imu_index = 1;
  for (int k = 1; k <= 40; ++k) {
    // IMU at 100 Hz with a little alternating noise that averages out per interval pair.
    for (; imu_index * 0.01 <= 0.025 * k + 1e-9; ++imu_index) {
      ImuSample imu;
      imu.time = Time::FromSeconds(imu_index * 0.01);
      imu.angular_velocity_rad_s.z() = omega;
      odometry.AddImu(imu);
    }
    odometry.AddTicks(Ticks(0.025 * k, 3, 3));  // equal wheels: encoders alone would say yaw 0
  }
  EXPECT_EQ(odometry.gyro_fallbacks(), 1);
  EXPECT_NEAR(odometry.pose().theta(), omega * 1.0, 1e-9);
  // Travelled 120 ticks along an arc of yaw 0.3: chord = s * sinc(0.15).
  const double s = 120 * DiffDriveParams{}.MetresPerTick();
  EXPECT_NEAR(odometry.pose().translation().norm(), s * std::sin(0.15) / 0.15, 1e-9);
}

TEST(WheelOdometryTest, ValidateNamesFieldValueAndRule) {
  DiffDriveParams robot;
  robot.wheel_radius_m = 0.0;
  robot.ticks_per_revolution = -3;
  EXPECT_THAT(robot.Validate(),
              testing::ElementsAre("diff_drive.wheel_radius_m = 0; must be > 0",
                                   "diff_drive.ticks_per_revolution = -3; must be > 0"));
  WheelOdometryOptions options;
  options.robot.track_width_m = -1.0;
  EXPECT_THAT(options.Validate(),
              testing::ElementsAre("wheel_odometry.diff_drive.track_width_m = -1; must be > 0"));
  EXPECT_TRUE(WheelOdometryOptions{}.Validate().empty());
}

}  // namespace
}  // namespace slamrig::slam
