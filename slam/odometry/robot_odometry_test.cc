#include "slam/odometry/robot_odometry.h"

#include <gtest/gtest.h>

namespace slamrig::slam {
namespace {

WheelTicks Ticks(std::int64_t ns, int right, int left) {
  WheelTicks t;
  t.time = Time{ns};
  t.right_ticks = {right};
  t.left_ticks = {left};
  return t;
}

ImuSample Gyro(std::int64_t ns, double yaw_rate) {
  ImuSample imu;
  imu.time = Time{ns};
  imu.angular_velocity_rad_s = Eigen::Vector3d(0.0, 0.0, yaw_rate);
  return imu;
}

TEST(RobotOdometryTest, IntegratesTicksWithTheGyroAsWheelOdometryDoes) {
  WheelOdometryOptions options;
  options.use_gyro = true;
  RobotOdometry robot(options);
  WheelOdometry reference(options);
  const std::vector<Record> records = {Ticks(0, 0, 0),        Gyro(10'000'000, 0.3),
                                       LaserScan{},           Ticks(25'000'000, 12, 8),
                                       Gyro(30'000'000, 0.2), Ticks(50'000'000, 11, 9)};
  int poses = 0;
  for (const Record& r : records) {
    const std::optional<OdometryPose> pose = robot.Add(r);
    if (const auto* imu = std::get_if<ImuSample>(&r)) {
      reference.AddImu(*imu);
      EXPECT_FALSE(pose);
    } else if (const auto* ticks = std::get_if<WheelTicks>(&r)) {
      const OdometryPose expected = reference.AddTicks(*ticks);
      ASSERT_TRUE(pose);
      EXPECT_EQ(pose->time, expected.time);
      EXPECT_EQ(pose->odom_from_base, expected.odom_from_base);
      ++poses;
    } else {
      EXPECT_FALSE(pose);
    }
  }
  EXPECT_EQ(robot.poses(), poses);
  EXPECT_EQ(robot.imu_samples(), 2);
  EXPECT_EQ(robot.pose(), reference.pose());
  // The gyro turned the robot: the pose is not the encoder-only one.
  EXPECT_GT(robot.pose().theta(), 0.0);
}

TEST(RobotOdometryTest, PassesLoggedPosesThrough) {
  RobotOdometry robot(WheelOdometryOptions{});
  const OdometryPose logged{Time{7}, Pose2(1.5, -2.0, 0.25)};
  const std::optional<OdometryPose> pose = robot.Add(Record{logged});
  ASSERT_TRUE(pose);
  EXPECT_EQ(pose->time, logged.time);
  EXPECT_EQ(pose->odom_from_base, logged.odom_from_base);
  EXPECT_EQ(robot.pose(), Pose2());  // nothing was integrated
}

}  // namespace
}  // namespace slamrig::slam
