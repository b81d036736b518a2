// Long simulator runs (label "integration"): the acceptance figures.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world_yaml.h"
#include "slam/odometry/wheel_odometry.h"

namespace slamrig::sim {
namespace {

struct LoopResult {
  double encoder_distance_m = 0.0;
  double true_distance_m = 0.0;
  double encoder_only_error_m = 0.0;  // dead reckoning from the encoders alone
  double encoder_gyro_error_m = 0.0;  // the robot's own encoder + gyro odometry
  int laps = 0;
  double seconds = 0.0;
};

// Drives the office loop and dead-reckons along the way.
LoopResult DriveOffice(SimulatorOptions options) {
  Simulator sim(options);
  const RobotSpec& robot = options.robot;
  slam::WheelOdometryOptions odometry_options;
  odometry_options.robot = NominalOdometry(robot);
  odometry_options.use_gyro = false;
  slam::WheelOdometry encoders_only(odometry_options);
  odometry_options.use_gyro = true;
  slam::WheelOdometry encoders_and_gyro(odometry_options);
  const double metres_per_tick =
      2.0 * std::numbers::pi * robot.wheels.radius_m / robot.encoders.ticks_per_revolution;

  LoopResult result;
  std::optional<Pose2> previous;
  auto consume = [&](const StepResult& step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      if (const auto* imu = std::get_if<ImuSample>(&step.records[i])) {
        encoders_and_gyro.AddImu(*imu);
      } else if (const auto* ticks = std::get_if<WheelTicks>(&step.records[i])) {
        encoders_only.AddTicks(*ticks);
        encoders_and_gyro.AddTicks(*ticks);
        double sum = 0.0;
        for (const auto t : ticks->right_ticks) sum += t;
        for (const auto t : ticks->left_ticks) sum += t;
        const double n = static_cast<double>(ticks->right_ticks.size() + ticks->left_ticks.size());
        result.encoder_distance_m += std::abs(sum / n) * metres_per_tick;
        const Pose2& truth = step.truth[i].map_from_base;
        if (previous)
          result.true_distance_m += (truth.translation() - previous->translation()).norm();
        previous = truth;
      }
    }
  };
  while (!sim.drive_finished() && sim.time().seconds() < 3600.0) consume(sim.Step());
  consume(sim.Flush());
  const Pose2 truth = sim.Truth().map_from_base;
  const Pose2& spawn = options.world.spawn;
  result.encoder_only_error_m =
      (truth.translation() - (spawn * encoders_only.pose()).translation()).norm();
  result.encoder_gyro_error_m =
      (truth.translation() - (spawn * encoders_and_gyro.pose()).translation()).norm();
  result.laps = sim.driver().laps_completed();
  result.seconds = sim.time().seconds();
  return result;
}

SimulatorOptions OfficeThreeLaps() {
  SimulatorOptions options;
  options.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  options.robot = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  options.world.drive.laps = 3;
  options.world.drive.speed_m_s = 0.5;
  return options;
}

TEST(SimIntegrationTest, ThreeOfficeLapsWithDefaultNoiseDriftMoreThanHalfAMetre) {
  const LoopResult r = DriveOffice(OfficeThreeLaps());
  std::printf(
      "office, 3 laps, default noise: %.1f s, %.1f m driven; dead reckoning ends %.2f m "
      "off from encoders alone, %.2f m off from encoders + gyro\n",
      r.seconds, r.true_distance_m, r.encoder_only_error_m, r.encoder_gyro_error_m);
  EXPECT_EQ(r.laps, 3);
  EXPECT_GT(r.encoder_only_error_m, 0.5);
  EXPECT_GT(r.encoder_gyro_error_m, 0.1);
}

TEST(SimIntegrationTest, WithoutNoiseOnAGrippyFloorEncoderDistanceMatchesWithinHalfAPercent) {
  SimulatorOptions options = OfficeThreeLaps();
  options.robot = WithoutNoise(options.robot);
  options.robot.lidar.enabled = false;  // not needed for odometry
  options.world.floor.mu = 1.0;
  for (ZoneSpec& zone : options.world.zones) zone.surface = options.world.floor;
  const LoopResult r = DriveOffice(options);
  std::printf(
      "office, 3 laps, no noise, mu = 1: encoder distance %.3f m, true distance %.3f m "
      "(ratio %.5f)\n",
      r.encoder_distance_m, r.true_distance_m, r.encoder_distance_m / r.true_distance_m);
  EXPECT_EQ(r.laps, 3);
  EXPECT_NEAR(r.encoder_distance_m / r.true_distance_m, 1.0, 0.005);
}

TEST(SimIntegrationTest, TheOfficeIcePatchMakesTheEncodersOverstateTheDistance) {
  // The robot speeds up out of the south-east corner on the ice patch: the wheels spin.
  SimulatorOptions icy = OfficeThreeLaps();
  icy.robot = WithoutNoise(icy.robot);
  icy.robot.lidar.enabled = false;
  icy.world.drive.laps = 1;
  SimulatorOptions dry = icy;
  for (ZoneSpec& zone : dry.world.zones) {
    if (zone.name == "ice") zone.surface = dry.world.floor;
  }
  const LoopResult on_ice = DriveOffice(icy), without_ice = DriveOffice(dry);
  const double excess_icy = on_ice.encoder_distance_m - on_ice.true_distance_m;
  const double excess_dry = without_ice.encoder_distance_m - without_ice.true_distance_m;
  std::printf(
      "office, 1 lap, no noise: encoders exceed the true distance by %.3f m with the ice "
      "patch, %.3f m without\n",
      excess_icy, excess_dry);
  EXPECT_GT(excess_icy, excess_dry + 0.05);
}

TEST(SimIntegrationTest, EveryWorldIsDrivenToTheEndByEveryRobot) {
  for (const char* world : {"office", "corridor", "two_rooms", "hall", "lab_map"}) {
    for (const char* robot : {"ece276a", "small_diff"}) {
      SimulatorOptions options;
      options.world = LoadWorldSpec(FindPresetFile(world, "worlds"));
      options.robot = LoadRobotSpec(FindPresetFile(robot, "robots"));
      options.robot.lidar.enabled = false;  // the drive does not depend on it
      Simulator sim(options);
      while (!sim.drive_finished() && sim.time().seconds() < 1200.0) sim.Step();
      EXPECT_TRUE(sim.drive_finished())
          << world << " with " << robot << " stuck at (" << sim.Truth().map_from_base.x() << ", "
          << sim.Truth().map_from_base.y() << ")";
    }
  }
}

}  // namespace
}  // namespace slamrig::sim
