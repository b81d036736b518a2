#include "sim/robot.h"

#include <algorithm>
#include <cmath>

#include "slam/types/check.h"

namespace slamrig::sim {
namespace {

constexpr double kGravity = 9.80665;

double MoveTowards(double value, double target, double max_step) {
  return value + std::clamp(target - value, -max_step, max_step);
}

}  // namespace

Robot::Robot(const RobotSpec& spec, World* world, const Pose2& map_from_base)
    : spec_(spec), world_(world) {
  SLAMRIG_CHECK(spec_.Validate().empty(), "invalid RobotSpec");
  const ChassisOptions& chassis = spec_.chassis;
  const WheelOptions& w = spec_.wheels;

  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(static_cast<float>(map_from_base.x()), static_cast<float>(map_from_base.y()));
  def.angle = static_cast<float>(map_from_base.theta());
  def.allowSleep = false;
  body_ = world_->b2world()->CreateBody(&def);
  b2PolygonShape footprint;
  footprint.SetAsBox(static_cast<float>(0.5 * chassis.length_m),
                     static_cast<float>(0.5 * chassis.width_m));
  b2FixtureDef fixture;
  fixture.shape = &footprint;
  fixture.density = 1.0f;
  fixture.friction = static_cast<float>(chassis.wall_friction);
  fixture.restitution = 0.0f;
  body_->CreateFixture(&fixture);

  mass_kg_ = chassis.mass_kg;
  inertia_kg_m2_ =
      chassis.yaw_inertia_kg_m2 > 0.0
          ? chassis.yaw_inertia_kg_m2
          : mass_kg_ * (chassis.length_m * chassis.length_m + chassis.width_m * chassis.width_m) /
                12.0;
  b2MassData mass;
  mass.mass = static_cast<float>(mass_kg_);
  mass.center.SetZero();
  mass.I = static_cast<float>(inertia_kg_m2_);
  body_->SetMassData(&mass);
  // Box2D stores mass and inertia as floats; use exactly what it integrates with.
  mass_kg_ = static_cast<double>(body_->GetMass());
  inertia_kg_m2_ = static_cast<double>(body_->GetInertia());

  // Physical geometry: nominal corrected by the calibration errors.
  const CalibrationErrors& cal = spec_.calibration;
  const double half_track = 0.5 * w.track_width_m * (1.0 + cal.track_width_error);
  const double load = mass_kg_ * kGravity * (1.0 - w.caster_load_fraction) / (2.0 * w.per_side);
  for (const bool right : {true, false}) {
    for (int i = 0; i < w.per_side; ++i) {
      WheelState wheel;
      wheel.right = right;
      const double x =
          w.per_side == 1 ? 0.0 : w.wheelbase_m * (0.5 - static_cast<double>(i) / (w.per_side - 1));
      wheel.position_m = Eigen::Vector2d(x, right ? -half_track : half_track);
      wheel.radius_m =
          w.radius_m * (1.0 + (right ? cal.right_radius_error : cal.left_radius_error));
      wheel.load_n = load;
      wheels_.push_back(wheel);
    }
  }
  integral_rad_.assign(wheels_.size(), 0.0);
}

Robot::~Robot() { world_->b2world()->DestroyBody(body_); }

Pose2 Robot::pose() const {
  const b2Vec2 p = body_->GetPosition();
  return Pose2(p.x, p.y, body_->GetAngle());
}

double Robot::unwrapped_yaw_rad() const { return body_->GetAngle(); }

Eigen::Vector2d Robot::velocity_m_s() const {
  const b2Vec2 v = body_->GetLinearVelocity();
  return {v.x, v.y};
}

double Robot::yaw_rate_rad_s() const { return body_->GetAngularVelocity(); }

void Robot::RampCommand(double dt_s) {
  const MotionLimits& l = spec_.limits;
  const double v = std::clamp(command_.v_m_s, -l.max_speed_m_s, l.max_speed_m_s);
  const double w = std::clamp(command_.omega_rad_s, -l.max_yaw_rate_rad_s, l.max_yaw_rate_rad_s);
  ramped_.v_m_s = MoveTowards(ramped_.v_m_s, v, l.max_accel_m_s2 * dt_s);
  ramped_.omega_rad_s = MoveTowards(ramped_.omega_rad_s, w, l.max_yaw_accel_rad_s2 * dt_s);
}

void Robot::ApplyWheelForces(double dt_s, int iterations) {
  RampCommand(dt_s);
  const WheelOptions& w = spec_.wheels;
  const MotorOptions& motor = spec_.motor;
  const double spin_inertia = w.spin_inertia_kg_m2;

  // Chassis velocity in base_link.
  const double yaw = body_->GetAngle();
  const double c = std::cos(yaw), s = std::sin(yaw);
  const b2Vec2 p = body_->GetPosition();
  const b2Vec2 v_world = body_->GetLinearVelocity();
  double vx = c * v_world.x + s * v_world.y;
  double vy = -s * v_world.x + c * v_world.y;
  double omega = body_->GetAngularVelocity();

  // Motors: a PI loop per wheel towards the speed its side needs (nominal geometry), with
  // conditional integration against wind-up; then rolling resistance brakes the wheel.
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    WheelState& wheel = wheels_[i];
    const Eigen::Vector2d contact(p.x + c * wheel.position_m.x() - s * wheel.position_m.y(),
                                  p.y + s * wheel.position_m.x() + c * wheel.position_m.y());
    const SurfaceSpec& surface = world_->SurfaceAt(contact);
    wheel.mu = surface.mu;
    const double side_speed =
        ramped_.v_m_s + (wheel.right ? 1.0 : -1.0) * 0.5 * w.track_width_m * ramped_.omega_rad_s;
    const double target = std::clamp(side_speed / w.radius_m, -motor.max_wheel_speed_rad_s,
                                     motor.max_wheel_speed_rad_s);
    const double error = target - wheel.spin_rad_s;
    const double unlimited =
        motor.kp_n_m_s_rad * error + motor.ki_n_m_rad * (integral_rad_[i] + error * dt_s);
    if (std::abs(unlimited) <= motor.max_torque_n_m) integral_rad_[i] += error * dt_s;
    wheel.motor_torque_n_m =
        std::clamp(motor.kp_n_m_s_rad * error + motor.ki_n_m_rad * integral_rad_[i],
                   -motor.max_torque_n_m, motor.max_torque_n_m);
    double spin = wheel.spin_rad_s + dt_s * wheel.motor_torque_n_m / spin_inertia;
    const double brake =
        dt_s * surface.rolling_resistance * wheel.load_n * wheel.radius_m / spin_inertia;
    spin = std::copysign(std::max(0.0, std::abs(spin) - brake), spin);
    wheel.spin_rad_s = spin;
  }

  // Tyre forces by sequential impulses. Per wheel the constraint velocity is the slip
  // (R * spin - u, -lateral); the soft-constraint impulse P satisfies slip_end = P / (k * load *
  // dt), with P clamped to the friction circle |P| <= mu * load * dt.
  std::vector<Eigen::Vector2d> impulse(wheels_.size(), Eigen::Vector2d::Zero());
  const double inv_m = 1.0 / mass_kg_, inv_i = 1.0 / inertia_kg_m2_;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (std::size_t i = 0; i < wheels_.size(); ++i) {
      WheelState& wheel = wheels_[i];
      const double x = wheel.position_m.x(), y = wheel.position_m.y(), r = wheel.radius_m;
      const double u = vx - omega * y;
      const double lateral = vy + omega * x;
      const Eigen::Vector2d slip(r * wheel.spin_rad_s - u, -lateral);
      const double gamma_x = 1.0 / (w.longitudinal_stiffness_s_m * wheel.load_n * dt_s);
      const double gamma_y = 1.0 / (w.lateral_stiffness_s_m * wheel.load_n * dt_s);
      // Solve (K + diag(gamma)) dP = slip - gamma * P for the 2x2 effective mass K.
      const double k11 = r * r / spin_inertia + inv_m + y * y * inv_i + gamma_x;
      const double k12 = -x * y * inv_i;
      const double k22 = inv_m + x * x * inv_i + gamma_y;
      const double rhs1 = slip.x() - gamma_x * impulse[i].x();
      const double rhs2 = slip.y() - gamma_y * impulse[i].y();
      const double det = k11 * k22 - k12 * k12;
      Eigen::Vector2d total =
          impulse[i] + Eigen::Vector2d(k22 * rhs1 - k12 * rhs2, k11 * rhs2 - k12 * rhs1) / det;
      const double limit = wheel.mu * wheel.load_n * dt_s;
      const double norm = total.norm();
      if (norm > limit) total *= norm > 0.0 ? limit / norm : 0.0;
      const Eigen::Vector2d delta = total - impulse[i];
      impulse[i] = total;
      vx += delta.x() * inv_m;
      vy += delta.y() * inv_m;
      omega += (x * delta.y() - y * delta.x()) * inv_i;
      wheel.spin_rad_s -= r * delta.x() / spin_inertia;
    }
  }

  // Ground truth of the contacts, then turn the wheels.
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    WheelState& wheel = wheels_[i];
    wheel.slip_m_s = wheel.radius_m * wheel.spin_rad_s - (vx - omega * wheel.position_m.y());
    wheel.skid_m_s = vy + omega * wheel.position_m.x();
    const double limit = wheel.mu * wheel.load_n * dt_s;
    wheel.friction_use = limit > 0.0 ? std::min(1.0, impulse[i].norm() / limit) : 1.0;
    wheel.angle_rad += wheel.spin_rad_s * dt_s;
  }
  body_->SetLinearVelocity(
      b2Vec2(static_cast<float>(c * vx - s * vy), static_cast<float>(s * vx + c * vy)));
  body_->SetAngularVelocity(static_cast<float>(omega));
}

}  // namespace slamrig::sim
