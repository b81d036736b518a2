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
  SLAMRIG_CHECK_VALID(spec_, "RobotSpec");
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
  deflection_m_.assign(wheels_.size(), Eigen::Vector2d::Zero());
  impulse_.assign(wheels_.size(), Eigen::Vector2d::Zero());
  contacts_.assign(wheels_.size(), Contact{});
}

Robot::~Robot() { world_->b2world()->DestroyBody(body_); }

void Robot::Teleport(const Pose2& map_from_base) {
  body_->SetTransform(
      b2Vec2(static_cast<float>(map_from_base.x()), static_cast<float>(map_from_base.y())),
      static_cast<float>(map_from_base.theta()));
  body_->SetLinearVelocity(b2Vec2(0.0f, 0.0f));
  body_->SetAngularVelocity(0.0f);
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    wheels_[i].spin_rad_s = 0.0;
    integral_rad_[i] = 0.0;
    deflection_m_[i].setZero();
  }
  ramped_ = VelocityCommand{};
}

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
  // s = (R * spin - u, -lateral). Implicit Euler on the brush model gives
  //   z' = (z + dt s') / (1 + a),  a = dt |v_roll| / L,  f = k z' + c s',
  // i.e. s' = (f - k z / (1 + a)) / d with d = k dt / (1 + a) + c: a soft constraint with
  // compliance gamma = 1 / (dt d) and a bias from the stored deflection. The impulse P = f dt is
  // clamped to the friction circle |P| <= mu * load * dt.
  const double inv_m = 1.0 / mass_kg_, inv_i = 1.0 / inertia_kg_m2_;
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    const WheelState& wheel = wheels_[i];
    const double k = w.contact_stiffness_per_m * wheel.load_n;
    const double relax =
        1.0 + dt_s * std::abs(wheel.radius_m * wheel.spin_rad_s) / w.relaxation_length_m;
    const double d = k * dt_s / relax + w.contact_damping_s_m * wheel.load_n;
    Contact& contact = contacts_[i];
    contact = {1.0 / (dt_s * d), k * deflection_m_[i].x() / relax / d,
               k * deflection_m_[i].y() / relax / d, relax};
    // The 2x2 effective mass K + gamma I stays the same over the iterations.
    const double x = wheel.position_m.x(), y = wheel.position_m.y(), r = wheel.radius_m;
    contact.k11 = r * r / spin_inertia + inv_m + y * y * inv_i + contact.gamma;
    contact.k12 = -x * y * inv_i;
    contact.k22 = inv_m + x * x * inv_i + contact.gamma;
    contact.det = contact.k11 * contact.k22 - contact.k12 * contact.k12;
    impulse_[i].setZero();
  }
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (std::size_t i = 0; i < wheels_.size(); ++i) {
      WheelState& wheel = wheels_[i];
      const Contact& contact = contacts_[i];
      const double x = wheel.position_m.x(), y = wheel.position_m.y(), r = wheel.radius_m;
      const double slip_x = r * wheel.spin_rad_s - (vx - omega * y);
      const double slip_y = -(vy + omega * x);
      // Solve (K + gamma I) dP = s - gamma P + bias for the 2x2 effective mass K.
      const double k11 = contact.k11, k12 = contact.k12, k22 = contact.k22, det = contact.det;
      const double rhs1 = slip_x - contact.gamma * impulse_[i].x() + contact.bias_x;
      const double rhs2 = slip_y - contact.gamma * impulse_[i].y() + contact.bias_y;
      Eigen::Vector2d total =
          impulse_[i] + Eigen::Vector2d(k22 * rhs1 - k12 * rhs2, k11 * rhs2 - k12 * rhs1) / det;
      const double limit = wheel.mu * wheel.load_n * dt_s;
      const double norm = total.norm();
      if (norm > limit) total *= norm > 0.0 ? limit / norm : 0.0;
      const Eigen::Vector2d delta = total - impulse_[i];
      impulse_[i] = total;
      vx += delta.x() * inv_m;
      vy += delta.y() * inv_m;
      omega += (x * delta.y() - y * delta.x()) * inv_i;
      wheel.spin_rad_s -= r * delta.x() / spin_inertia;
    }
  }

  body_->SetLinearVelocity(
      b2Vec2(static_cast<float>(c * vx - s * vy), static_cast<float>(s * vx + c * vy)));
  body_->SetAngularVelocity(static_cast<float>(omega));
}

void Robot::FinishStep(double dt_s) {
  // The slip the tyres really saw: with the chassis velocity after Box2D resolved its contacts
  // (a robot pushing a wall is stopped there, not in the tyre solve).
  const double yaw = body_->GetAngle();
  const double c = std::cos(yaw), s = std::sin(yaw);
  const b2Vec2 v_world = body_->GetLinearVelocity();
  const double vx = c * v_world.x + s * v_world.y;
  const double vy = -s * v_world.x + c * v_world.y;
  const double omega = body_->GetAngularVelocity();
  const double spin_inertia = spec_.wheels.spin_inertia_kg_m2;
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    WheelState& wheel = wheels_[i];
    const double r = wheel.radius_m;
    // Box2D's contacts may have changed the chassis velocity the tyres were solved against (a
    // wall stops the chassis, not the wheels): one more longitudinal pass drags each wheel
    // towards the chassis as it now moves, the chassis held fixed, so that a stalled wheel does
    // not creep. Without contacts the tyre constraint already holds and this adds nothing.
    const Contact& contact = contacts_[i];
    const double slip = r * wheel.spin_rad_s - (vx - omega * wheel.position_m.y());
    const double k = r * r / spin_inertia + contact.gamma;
    double total = impulse_[i].x() + (slip - contact.gamma * impulse_[i].x() + contact.bias_x) / k;
    const double limit_x = std::sqrt(std::max(
        0.0, std::pow(wheel.mu * wheel.load_n * dt_s, 2) - impulse_[i].y() * impulse_[i].y()));
    total = std::clamp(total, -limit_x, limit_x);
    wheel.spin_rad_s -= r * (total - impulse_[i].x()) / spin_inertia;
    impulse_[i].x() = total;

    wheel.slip_m_s = r * wheel.spin_rad_s - (vx - omega * wheel.position_m.y());
    wheel.skid_m_s = vy + omega * wheel.position_m.x();
    // The tread deflection, capped where the tyre slides.
    Eigen::Vector2d& z = deflection_m_[i];
    z = (z + dt_s * Eigen::Vector2d(wheel.slip_m_s, -wheel.skid_m_s)) / contact.relax;
    const double max_deflection = wheel.mu / spec_.wheels.contact_stiffness_per_m;
    if (z.norm() > max_deflection) z *= max_deflection / z.norm();
    const double limit = wheel.mu * wheel.load_n * dt_s;
    wheel.friction_use = limit > 0.0 ? std::min(1.0, impulse_[i].norm() / limit) : 1.0;
    wheel.angle_rad += wheel.spin_rad_s * dt_s;
  }
}

}  // namespace slamrig::sim
