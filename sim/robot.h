#pragma once

#include <box2d/box2d.h>

#include <Eigen/Core>
#include <vector>

#include "sim/driver.h"
#include "sim/robot_spec.h"
#include "sim/world.h"
#include "slam/types/pose2.h"

namespace slamrig::sim {

/// What one wheel is doing: ground truth only, never seen by the SLAM stack.
struct WheelState {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  ///< contact point in base_link
  bool right = true;                                     ///< right side (else left)
  double radius_m = 0.0;                                 ///< physical radius
  double load_n = 0.0;                                   ///< normal load
  double spin_rad_s = 0.0;        ///< wheel spin rate, positive rolling forwards
  double angle_rad = 0.0;         ///< total rotation since the start (what the encoder counts)
  double motor_torque_n_m = 0.0;  ///< torque of the last step, after the limit
  double mu = 0.0;                ///< friction coefficient under the wheel
  double slip_m_s = 0.0;          ///< wheel surface speed minus ground speed, forwards
  double skid_m_s = 0.0;          ///< sideways ground speed of the contact point
  double friction_use = 0.0;      ///< |tyre force| / (mu * load): 1 means sliding
};

/// A differential-drive (or skid-steer) robot as a Box2D body driven by its wheels. Each wheel
/// has its own spin state and a motor with a torque limit and a PI speed loop towards the speed
/// its side needs for the commanded (v, omega), computed with the nominal radius and track.
/// Each tyre contact is a first-order brush model with a relaxation length (Pacejka, "Tire and
/// Vehicle Dynamics", 3rd ed., Ch. 7): a tread deflection z with dz/dt = slip - |v_roll| / L * z,
/// force k z + c slip, capped at mu * load on the friction circle (longitudinal and lateral
/// together). Tyre forces, wheel spin and chassis velocity are solved implicitly by sequential
/// impulses (Catto, "Iterative Dynamics with Temporal Coherence", GDC 2005, with the soft
/// constraints of Box2D), so the stiff contact stays stable at physics rates of 200 Hz. Rolling
/// resistance brakes each wheel.
class Robot {
 public:
  /// Creates the body in `world` at `map_from_base`. `spec` must be valid (checked).
  Robot(const RobotSpec& spec, World* world, const Pose2& map_from_base);
  ~Robot();
  Robot(const Robot&) = delete;
  Robot& operator=(const Robot&) = delete;

  /// The velocity the robot should drive at; the base controller ramps towards it within the
  /// motion limits.
  void SetCommand(const VelocityCommand& command) { command_ = command; }

  /// Runs the motors and the tyre forces for a physics step of `dt_s`, changing the body's
  /// velocity (`iterations` sequential-impulse passes). Call before stepping the Box2D world.
  void ApplyWheelForces(double dt_s, int iterations);
  /// Completes the step after the Box2D world moved: tread deflections from the slip the tyres
  /// really saw, contact state for the ground truth, wheel rotation for the encoders.
  void FinishStep(double dt_s);

  /// Puts the robot down at `map_from_base` at rest (a kidnapping): body and wheels stop, the
  /// tyres and speed loops relax, the wheels keep their rotation (the encoders notice nothing).
  void Teleport(const Pose2& map_from_base);

  /// Pose of base_link in the map frame.
  Pose2 pose() const;
  /// Heading without wrapping (continuous over turns), rad.
  double unwrapped_yaw_rad() const;
  /// Velocity of base_link in the map frame, m/s.
  Eigen::Vector2d velocity_m_s() const;
  /// Yaw rate, rad/s.
  double yaw_rate_rad_s() const;
  /// The wheels: right side front to back, then left side front to back.
  const std::vector<WheelState>& wheels() const { return wheels_; }
  /// Driven wheels on the right side (the first entries of wheels()).
  int num_right_wheels() const { return spec_.wheels.per_side; }
  /// Driven wheels on the left side (the last entries of wheels()).
  int num_left_wheels() const { return spec_.wheels.per_side; }
  /// The velocity the base controller currently drives at (after ramps).
  const VelocityCommand& ramped_command() const { return ramped_; }
  /// The preset it was built from.
  const RobotSpec& spec() const { return spec_; }
  /// Its Box2D body (the lidar caster ignores its fixtures).
  const b2Body* body() const { return body_; }

 private:
  void RampCommand(double dt_s);

  RobotSpec spec_;
  World* world_;
  b2Body* body_ = nullptr;
  double mass_kg_ = 0.0;
  double inertia_kg_m2_ = 0.0;
  std::vector<WheelState> wheels_;
  std::vector<double> integral_rad_;           // PI speed loop state per wheel
  std::vector<Eigen::Vector2d> deflection_m_;  // tread deflection per wheel, base_link axes
  std::vector<Eigen::Vector2d> impulse_;       // tyre impulse per wheel in the last step
  struct Contact {
    double gamma = 0.0;                      // soft-constraint compliance
    double bias_x = 0.0;                     // stored-deflection bias, longitudinal
    double bias_y = 0.0;                     // and lateral
    double relax = 1.0;                      // deflection relaxation factor 1 + dt |v_roll| / L
    double k11 = 0.0, k12 = 0.0, k22 = 0.0;  // effective mass K + gamma I of the step
    double det = 1.0;                        // its determinant
  };
  std::vector<Contact> contacts_;  // per wheel, for the step under way
  VelocityCommand command_;
  VelocityCommand ramped_;
};

}  // namespace slamrig::sim
