#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::sim {
namespace {

std::int64_t PeriodNs(double rate_hz) { return std::llround(1e9 / rate_hz); }

}  // namespace

std::vector<std::string> SimulatorOptions::Validate() const {
  Rules rules;
  rules.Nested("world", world.Validate())
      .Nested("robot", robot.Validate())
      .InRange("physics_rate_hz", physics_rate_hz, 50.0, 10000.0)
      .AtLeast("traction_iterations", traction_iterations, 1)
      .AtLeast("velocity_iterations", velocity_iterations, 1)
      .AtLeast("position_iterations", position_iterations, 1);
  // The speed loop is integrated explicitly: its gain must not overshoot within one step.
  const double dt = 1.0 / physics_rate_hz;
  const double loop_gain = robot.motor.kp_n_m_s_rad * dt / robot.wheels.spin_inertia_kg_m2;
  if (rules.errors().empty()) {
    rules.Require(loop_gain < 1.0, "robot.motor.kp_n_m_s_rad", robot.motor.kp_n_m_s_rad,
                  "kp / physics_rate_hz / wheels.spin_inertia_kg_m2 = " + FormatNumber(loop_gain) +
                      " must be < 1 for a stable speed loop");
  }
  return rules.errors();
}

Simulator::Simulator(const SimulatorOptions& options)
    : options_(options), driver_(options.world.drive) {
  SLAMRIG_CHECK_VALID(options_, "SimulatorOptions");
  world_ = std::make_unique<World>(options_.world);
  robot_ = std::make_unique<Robot>(options_.robot, world_.get(), options_.world.spawn);
  caster_ = std::make_unique<RayCaster>(world_->b2world(), robot_->body(), &world_->materials());
  step_ns_ = PeriodNs(options_.physics_rate_hz);
  step_s_ = static_cast<double>(step_ns_) * 1e-9;

  const RobotSpec& robot = options_.robot;
  if (robot.encoders.enabled) {
    encoders_.emplace(robot.encoders, robot_->num_right_wheels(), robot_->num_left_wheels(),
                      options_.seed, robot.wheels.radius_m);
    encoder_period_ns_ = PeriodNs(robot.encoders.rate_hz);
  }
  if (robot.imu.enabled) {
    imu_.emplace(robot.imu, options_.seed);
    imu_period_ns_ = PeriodNs(robot.imu.rate_hz);
  }
  if (robot.lidar.enabled) {
    lidar_.emplace(robot.lidar, options_.seed);
    scan_period_ns_ = PeriodNs(robot.lidar.rate_hz);
    rays_.resize(static_cast<std::size_t>(robot.lidar.num_beams));
    true_ranges_.resize(rays_.size());
  }
  history_.push_back(TakeSnapshot());
}

Simulator::~Simulator() = default;

Simulator::Snapshot Simulator::TakeSnapshot() const {
  Snapshot s;
  s.time = time_;
  const Pose2 pose = robot_->pose();
  s.x_m = pose.x();
  s.y_m = pose.y();
  s.yaw_rad = robot_->unwrapped_yaw_rad();
  s.velocity_m_s = robot_->velocity_m_s();
  s.yaw_rate_rad_s = robot_->yaw_rate_rad_s();
  s.wheels = robot_->wheels();
  return s;
}

StepResult Simulator::Step() {
  const Pose2 pose = robot_->pose();
  robot_->SetCommand(override_ ? *override_ : driver_.Update(time_, pose));
  world_->MoveObstacles(time_, step_s_);
  robot_->ApplyWheelForces(step_s_, options_.traction_iterations);
  world_->b2world()->Step(static_cast<float>(step_s_), options_.velocity_iterations,
                          options_.position_iterations);
  robot_->FinishStep(step_s_);
  time_.ns += step_ns_;
  history_.push_back(TakeSnapshot());
  history_.back().jump_before = teleported_;
  teleported_ = false;

  MeasureEncoders();
  MeasureImu();
  MeasureLidar();

  // Forget history no pending scan or sample can need any more.
  const Time keep_from = lidar_ ? std::min(ScanStart(next_scan_), time_) : time_;
  while (history_.size() > 2 && history_[1].time <= keep_from) history_.pop_front();
  return Release(false);
}

StepResult Simulator::Flush() { return Release(true); }

void Simulator::Teleport(const Pose2& map_from_base) {
  robot_->Teleport(map_from_base);
  teleported_ = true;
}

std::pair<std::size_t, double> Simulator::Locate(Time time) const {
  SLAMRIG_CHECK(
      history_.size() >= 2 && time >= history_.front().time && time <= history_.back().time,
      "time outside the kept history");
  const auto offset = time.ns - history_.front().time.ns;
  std::size_t j = static_cast<std::size_t>(offset / step_ns_);
  if (j >= history_.size() - 1) j = history_.size() - 2;
  const double f =
      static_cast<double>(time.ns - history_[j].time.ns) / static_cast<double>(step_ns_);
  return {j, f};
}

TruthSample Simulator::TruthAt(Time time) const {
  if (history_.size() == 1) {
    SLAMRIG_CHECK(time == history_.front().time, "time outside the kept history");
    const Snapshot& s = history_.front();
    return {time, Pose2(s.x_m, s.y_m, s.yaw_rad), s.velocity_m_s, s.yaw_rate_rad_s, s.wheels, {}};
  }
  const auto [j, f] = Locate(time);
  const Snapshot& a = history_[j];
  const Snapshot& b = history_[j + 1];
  TruthSample truth;
  truth.time = time;
  if (b.jump_before) {
    // No sweep across a teleport: before it the old pose, after it the new one.
    const Snapshot& s = f > 0.0 ? b : a;
    truth.map_from_base = Pose2(s.x_m, s.y_m, s.yaw_rad);
  } else {
    truth.map_from_base = Pose2(a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m),
                                a.yaw_rad + f * (b.yaw_rad - a.yaw_rad));
  }
  // Box2D moves with the velocity of the step's end over the whole step (semi-implicit Euler).
  const Snapshot& step = f > 0.0 ? b : a;
  truth.velocity_m_s = step.velocity_m_s;
  truth.yaw_rate_rad_s = step.yaw_rate_rad_s;
  truth.wheels = step.wheels;
  return truth;
}

TruthSample Simulator::Truth() const { return TruthAt(time_); }

void Simulator::Emit(Record record, std::vector<float> true_ranges_m) {
  // Keep the held records sorted by time; equal times stay in the order they were measured.
  const Time time = RecordTime(record);
  auto it = pending_.end();
  while (it != pending_.begin() && RecordTime(std::prev(it)->record) > time) --it;
  it = pending_.insert(it, Pending{std::move(record), TruthAt(time)});
  it->truth.true_ranges_m = std::move(true_ranges_m);
}

void Simulator::MeasureEncoders() {
  if (!encoders_) return;
  std::vector<double> angles(robot_->wheels().size());
  while (next_encoder_ * encoder_period_ns_ <= time_.ns) {
    const Time t{next_encoder_ * encoder_period_ns_};
    const auto [j, f] = Locate(t);
    for (std::size_t i = 0; i < angles.size(); ++i) {
      const double a0 = history_[j].wheels[i].angle_rad, a1 = history_[j + 1].wheels[i].angle_rad;
      angles[i] = a0 + f * (a1 - a0);
    }
    Emit(encoders_->Measure(t, angles));
    ++next_encoder_;
  }
}

void Simulator::MeasureImu() {
  if (!imu_) return;
  const ImuOptions& o = options_.robot.imu;
  while (next_imu_ * imu_period_ns_ <= time_.ns) {
    const Time t{next_imu_ * imu_period_ns_};
    const auto [j, f] = Locate(t);
    const Snapshot& a = history_[j];
    const Snapshot& b = history_[j + 1];
    // True motion of the step holding t: constant acceleration, the end velocity's yaw rate.
    // (A teleport is not felt: the robot is put down at rest.)
    const Eigen::Vector2d accel_world =
        b.jump_before ? Eigen::Vector2d::Zero()
                      : Eigen::Vector2d((b.velocity_m_s - a.velocity_m_s) / step_s_);
    const double yaw_accel = b.jump_before ? 0.0 : (b.yaw_rate_rad_s - a.yaw_rate_rad_s) / step_s_;
    const double w = b.yaw_rate_rad_s;
    const double yaw = b.jump_before ? b.yaw_rad : a.yaw_rad + f * (b.yaw_rad - a.yaw_rad);
    const double c = std::cos(yaw), s = std::sin(yaw);
    Eigen::Vector2d accel(c * accel_world.x() + s * accel_world.y(),
                          -s * accel_world.x() + c * accel_world.y());
    // Lever arm of an IMU away from base_link: tangential and centripetal terms.
    accel += Eigen::Vector2d(-yaw_accel * o.mount.y_m - w * w * o.mount.x_m,
                             yaw_accel * o.mount.x_m - w * w * o.mount.y_m);
    Emit(imu_->Measure(t, Eigen::Vector3d(0.0, 0.0, w),
                       Eigen::Vector3d(accel.x(), accel.y(), o.gravity_m_s2)));
    ++next_imu_;
  }
}

Time Simulator::ScanStart(std::int64_t k) const { return Time{k * scan_period_ns_}; }

Time Simulator::ScanEnd(std::int64_t k) const {
  const LidarOptions& o = options_.robot.lidar;
  return AddSeconds(ScanStart(k), (o.num_beams - 1) * o.time_increment_s());
}

void Simulator::MeasureLidar() {
  if (!lidar_) return;
  const LidarOptions& o = options_.robot.lidar;
  while (ScanEnd(next_scan_) <= time_) {
    const Time start = ScanStart(next_scan_);
    const double beam_dt = o.time_increment_s();
    const double angle0 = o.mount.yaw_rad + o.angle_min_rad();
    const double increment = o.angle_increment_rad();
    const auto [j0, f0] = Locate(start);
    // Each beam leaves from where the laser is at the beam's own time. Within one physics step the
    // pose moves linearly with the beam index, so the beam directions and the mount's rotation are
    // advanced by a fixed rotation per beam, recomputed exactly at the start of every step.
    const double steps_per_beam = beam_dt / step_s_;
    std::size_t step = history_.size();                                     // none yet
    double x0 = 0.0, y0 = 0.0, yaw0 = 0.0, dx = 0.0, dy = 0.0, dyaw = 0.0;  // the step's motion
    double c = 1.0, s = 0.0, dc = 1.0, ds = 0.0;                // cos/sin of yaw and beam angle
    double yaw_c = 1.0, yaw_s = 0.0, dir_c = 1.0, dir_s = 0.0;  // per-beam rotations
    const double base = static_cast<double>(j0) + f0;
    const std::size_t last_step = history_.size() - 2;
    const double mount_x = o.mount.x_m, mount_y = o.mount.y_m;
    for (std::size_t i = 0; i < rays_.size(); ++i) {
      const double u = base + static_cast<double>(i) * steps_per_beam;
      std::size_t j = std::min(static_cast<std::size_t>(u), last_step);
      double f = u - static_cast<double>(j);
      if (f == 0.0 && j > 0 && history_[j + 1].jump_before) {
        // Exactly at a teleport: still the old pose, the end of the step before.
        --j;
        f = 1.0;
      }
      if (j != step) {
        step = j;
        const Snapshot& a = history_[j];
        const Snapshot& b = history_[j + 1];
        // Across a teleport the beams after it see the new pose, without a sweep.
        const Snapshot& from = b.jump_before ? b : a;
        x0 = from.x_m;
        y0 = from.y_m;
        yaw0 = from.yaw_rad;
        dx = b.x_m - from.x_m;
        dy = b.y_m - from.y_m;
        dyaw = b.yaw_rad - from.yaw_rad;
        const double yaw = yaw0 + f * dyaw;
        const double angle = yaw + angle0 + static_cast<double>(i) * increment;
        c = std::cos(yaw);
        s = std::sin(yaw);
        dc = std::cos(angle);
        ds = std::sin(angle);
        const double yaw_step = dyaw * steps_per_beam;
        yaw_c = std::cos(yaw_step);
        yaw_s = std::sin(yaw_step);
        dir_c = std::cos(yaw_step + increment);
        dir_s = std::sin(yaw_step + increment);
      } else {
        const double c_next = c * yaw_c - s * yaw_s;
        s = s * yaw_c + c * yaw_s;
        c = c_next;
        const double dc_next = dc * dir_c - ds * dir_s;
        ds = ds * dir_c + dc * dir_s;
        dc = dc_next;
      }
      Ray& ray = rays_[i];
      ray.origin = Eigen::Vector2d(x0 + f * dx + c * mount_x - s * mount_y,
                                   y0 + f * dy + s * mount_x + c * mount_y);
      ray.angle_rad = yaw0 + f * dyaw + angle0 + static_cast<double>(i) * increment;
      ray.direction = Eigen::Vector2d(dc, ds);
    }
    caster_->Cast(rays_, o.range_max_m, true_ranges_);
    Emit(lidar_->MakeScan(start, true_ranges_),
         std::vector<float>(true_ranges_.begin(), true_ranges_.end()));
    ++next_scan_;
  }
}

Time Simulator::released_before() const {
  // Records up to now are measured; a scan in progress holds back those from its start on.
  const Time after_now{time_.ns + 1};
  return lidar_ ? std::min(ScanStart(next_scan_), after_now) : after_now;
}

StepResult Simulator::Release(bool all) {
  StepResult result;
  result.time = time_;
  const Time watermark =
      (lidar_ && !all) ? ScanStart(next_scan_) : Time{std::numeric_limits<std::int64_t>::max()};
  while (!pending_.empty() && RecordTime(pending_.front().record) < watermark) {
    result.records.push_back(std::move(pending_.front().record));
    result.truth.push_back(std::move(pending_.front().truth));
    pending_.pop_front();
  }
  return result;
}

}  // namespace slamrig::sim
