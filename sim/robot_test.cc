#include "sim/robot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "sim/simulator.h"

namespace slamrig::sim {
namespace {

// What the encoders say against what really happened, over a run.
struct Distances {
  double encoder_m = 0.0;        // sum of |mean wheel travel| per sample, nominal radius
  double truth_m = 0.0;          // true path length at the encoder samples
  double encoder_yaw_rad = 0.0;  // sum of the wheel-difference yaw increments, nominal track
  double truth_yaw_rad = 0.0;    // true heading change
  TruthSample last;
};

SimulatorOptions Options(RobotSpec robot, std::vector<ScheduleSegment> schedule) {
  SimulatorOptions o;
  o.robot = std::move(robot);
  o.robot.lidar.enabled = false;  // not needed here, and the physics does not depend on it
  o.world.drive.mode = DriveMode::kSchedule;
  o.world.drive.schedule = std::move(schedule);
  return o;
}

Distances Drive(const SimulatorOptions& options, double seconds) {
  Simulator sim(options);
  const WheelOptions& w = options.robot.wheels;
  const double metres_per_tick =
      2.0 * std::numbers::pi * w.radius_m / options.robot.encoders.ticks_per_revolution;
  Distances d;
  std::optional<TruthSample> previous;
  while (sim.time().seconds() < seconds) {
    const StepResult step = sim.Step();
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      const auto* ticks = std::get_if<WheelTicks>(&step.records[i]);
      if (ticks == nullptr) continue;
      double right = 0.0, left = 0.0;
      for (const auto t : ticks->right_ticks) right += t;
      for (const auto t : ticks->left_ticks) left += t;
      right *= metres_per_tick / static_cast<double>(ticks->right_ticks.size());
      left *= metres_per_tick / static_cast<double>(ticks->left_ticks.size());
      d.encoder_m += std::abs(0.5 * (right + left));
      d.encoder_yaw_rad += (right - left) / w.track_width_m;
      const TruthSample& truth = step.truth[i];
      if (previous) {
        d.truth_m +=
            (truth.map_from_base.translation() - previous->map_from_base.translation()).norm();
        d.truth_yaw_rad +=
            NormalizeAngle(truth.map_from_base.theta() - previous->map_from_base.theta());
      }
      previous = truth;
    }
  }
  d.last = sim.Truth();
  return d;
}

TEST(RobotTest, EncoderDistanceMatchesTruthWithoutNoiseOnAGrippyFloor) {
  for (const std::string name : {"ece276a", "small_diff"}) {
    RobotSpec robot;
    if (name == "small_diff") {
      robot.wheels.radius_m = 0.035;
      robot.wheels.track_width_m = 0.23;
      robot.wheels.per_side = 1;
      robot.wheels.wheelbase_m = 0.0;
      robot.wheels.spin_inertia_kg_m2 = 0.002;
      robot.wheels.caster_load_fraction = 0.2;
      robot.motor = MotorOptions{0.6, 0.15, 1.0, 25.0};
      robot.encoders.ticks_per_revolution = 2578;
    }
    auto options =
        Options(WithoutNoise(robot), {{4.0, 0.5, 0.0}, {6.0, 0.5, 0.4}, {4.0, 0.3, -0.3}});
    options.world.floor.mu = 1.2;
    const Distances d = Drive(options, 14.0);
    EXPECT_GT(d.truth_m, 5.0) << name;
    EXPECT_NEAR(d.encoder_m / d.truth_m, 1.0, 0.005) << name;
  }
}

TEST(RobotTest, IcePatchMakesTheEncodersOverstateTheDistance) {
  // Pull away on an ice patch and drive on across it onto the dry floor: the wheels spin up
  // faster than the robot can follow, so they turn further than it travels.
  auto options = Options(WithoutNoise(RobotSpec{}), {{8.0, 0.8, 0.0}});
  const Distances dry = Drive(options, 8.0);
  ZoneSpec ice;
  ice.name = "ice";
  ice.shape.center_m = {0.5, 0.0};
  ice.shape.size_m = {3.0, 3.0};
  ice.surface = SurfaceSpec{0.08, 0.01};
  options.world.zones.push_back(ice);
  const Distances icy = Drive(options, 8.0);
  EXPECT_NEAR(dry.encoder_m / dry.truth_m, 1.0, 0.002);
  EXPECT_GT(icy.encoder_m, icy.truth_m + 0.05);
  EXPECT_LT(icy.truth_m, dry.truth_m);
  std::printf("pulling away on ice: encoders %.3f m, truth %.3f m (dry: %.3f m, %.3f m)\n",
              icy.encoder_m, icy.truth_m, dry.encoder_m, dry.truth_m);
}

TEST(RobotTest, WheelsSlideOnIceWhenAccelerating) {
  auto options = Options(WithoutNoise(RobotSpec{}), {{1.0, 0.8, 0.0}});
  options.world.floor.mu = 0.08;
  Simulator sim(options);
  while (sim.time().seconds() < 0.5) sim.Step();
  for (const WheelState& w : sim.Truth().wheels) {
    EXPECT_EQ(w.mu, 0.08);
    EXPECT_GT(w.friction_use, 0.99);
    EXPECT_GT(w.slip_m_s, 0.02);
  }
}

TEST(RobotTest, WrongWheelRadiusScalesTheEncoderDistance) {
  RobotSpec robot = WithoutNoise(RobotSpec{});
  robot.calibration.left_radius_error = 0.01;
  robot.calibration.right_radius_error = 0.01;
  const Distances d = Drive(Options(robot, {{8.0, 0.5, 0.0}}), 8.0);
  EXPECT_NEAR(d.encoder_m / d.truth_m, 1.0 / 1.01, 0.001);
}

TEST(RobotTest, SkidSteeringTurnsLessThanTheWheelsSay) {
  // The four-wheel robot's wheels skid sideways in a turn: its yaw rate is about half of what
  // the wheel speed difference implies, the familiar skid-steer "effective track" of ~2x.
  const Distances skid = Drive(Options(WithoutNoise(RobotSpec{}), {{6.0, 0.0, 0.8}}), 6.0);
  EXPECT_GT(skid.truth_yaw_rad, 0.5);
  EXPECT_GT(skid.encoder_yaw_rad / skid.truth_yaw_rad, 1.5);
  EXPECT_LT(skid.encoder_yaw_rad / skid.truth_yaw_rad, 3.0);
}

TEST(RobotTest, PushingAWallSpinsStrongWheelsAndStallsWeakOnes) {
  ShapeSpec wall;
  wall.center_m = {1.5, 0.0};
  wall.size_m = {0.2, 4.0};
  for (const double max_torque : {4.0, 1.0}) {
    auto options = Options(WithoutNoise(RobotSpec{}), {{6.0, 0.5, 0.0}});
    options.robot.motor.max_torque_n_m = max_torque;
    options.world.walls.push_back(wall);
    const Distances d = Drive(options, 6.0);
    EXPECT_LT(d.last.map_from_base.x(), 1.5 - 0.1 - 0.275 + 0.02);  // stopped at the wall
    // Traction saturates at mu * load * radius = 0.8 * 19.6 N * 0.127 m = 2.0 N m per wheel.
    const double traction_torque = 0.8 * 8.0 * 9.80665 / 4.0 * 0.127;
    for (const WheelState& w : d.last.wheels) {
      if (max_torque > traction_torque) {
        // The motor wins: the wheel spins at its target speed, sliding on the floor.
        EXPECT_NEAR(w.spin_rad_s, 0.5 / 0.127, 0.05);
        EXPECT_GT(w.friction_use, 0.99);
      } else {
        // The motor stalls at its torque limit and the encoders stop.
        EXPECT_NEAR(std::abs(w.motor_torque_n_m), max_torque, 1e-9);
        EXPECT_NEAR(w.spin_rad_s, 0.0, 0.01);
      }
    }
    if (max_torque > traction_torque) {
      EXPECT_GT(d.encoder_m, d.truth_m + 1.0);
    } else {
      EXPECT_LT(d.encoder_m, d.truth_m + 0.05);
    }
  }
}

}  // namespace
}  // namespace slamrig::sim
