#include "slam/pf/testing/synthetic_run.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace slamrig::slam::testing {

std::vector<Eigen::Vector2d> OfficeLoop() {
  return {{1.5, 1.5}, {18.5, 1.5}, {18.5, 10.5}, {1.5, 10.5}};
}

SyntheticRun MakeSyntheticRun(const SegmentWorld& world, const SyntheticRunOptions& options) {
  SyntheticRun run;
  RandomEngine motion_rng(options.seed);
  RandomEngine lidar_rng(options.seed * 7919 + 1);
  const std::vector<Eigen::Vector2d>& wp = options.waypoints;
  const std::size_t num_wp = wp.size();
  const Eigen::Vector2d first_leg = wp[1 % num_wp] - wp[0];
  Pose2 pose(wp[0].x(), wp[0].y(), std::atan2(first_leg.y(), first_leg.x()));

  const std::int64_t dt_ns = 1'000'000;  // 1 kHz truth
  const double dt = 1e-3;
  const std::int64_t scan_period =
      static_cast<std::int64_t>(std::llround(1e9 / options.scan_rate_hz));
  const std::int64_t encoder_period =
      static_cast<std::int64_t>(std::llround(1e9 / options.encoder_rate_hz));
  const std::int64_t imu_period =
      static_cast<std::int64_t>(std::llround(1e9 / options.imu_rate_hz));
  const double metres_per_tick = options.robot.MetresPerTick();
  const double half_track = 0.5 * options.robot.track_width_m;

  std::size_t target = 1 % num_wp;
  int laps_done = 0;
  double right_accum = 0.0, left_accum = 0.0;  // measured wheel travel not yet reported
  double interval_right = 0.0, interval_left = 0.0;
  double omega = 0.0;
  for (std::int64_t t_ns = 0;; t_ns += dt_ns) {
    const Time now = Time::FromNanoseconds(t_ns);
    if (t_ns % imu_period == 0) {
      ImuSample imu;
      imu.time = now;
      imu.angular_velocity_rad_s.z() =
          omega + options.gyro_bias_rad_s + options.gyro_sigma_rad_s * StandardNormal(motion_rng);
      imu.linear_acceleration_m_s2.z() = 9.81;
      run.records.push_back(imu);
    }
    if (t_ns > 0 && t_ns % encoder_period == 0) {
      // Measured travel: systematic scale error and per-interval noise, then quantised to ticks.
      right_accum += interval_right * (1.0 + options.right_scale_error +
                                       options.wheel_noise * StandardNormal(motion_rng));
      left_accum += interval_left * (1.0 + options.left_scale_error +
                                     options.wheel_noise * StandardNormal(motion_rng));
      interval_right = interval_left = 0.0;
      const auto right_ticks = static_cast<std::int32_t>(std::trunc(right_accum / metres_per_tick));
      const auto left_ticks = static_cast<std::int32_t>(std::trunc(left_accum / metres_per_tick));
      right_accum -= right_ticks * metres_per_tick;
      left_accum -= left_ticks * metres_per_tick;
      run.records.push_back(WheelTicks{now, {right_ticks, right_ticks}, {left_ticks, left_ticks}});
    }
    // The scan goes last among records with its stamp: odometry up to its time belongs to it.
    if (t_ns % scan_period == 0) {
      run.records.push_back(world.Scan(pose, now, options.lidar, &lidar_rng));
      run.truth.push_back(GroundTruthPose{now, pose});
      ++run.num_scans;
    }
    if (laps_done >= options.laps || now.seconds() >= options.max_duration_s) break;

    // Carrot controller: turn towards the next waypoint, slow down while the heading is off.
    const Eigen::Vector2d to_target = wp[target] - pose.translation();
    if (to_target.norm() < 0.3) {
      target = (target + 1) % num_wp;
      if (target == 1 % num_wp) ++laps_done;
      continue;
    }
    const double heading_error =
        NormalizeAngle(std::atan2(to_target.y(), to_target.x()) - pose.theta());
    omega = std::clamp(2.0 * heading_error, -1.0, 1.0);
    const double v = options.speed_m_s * std::max(0.0, std::cos(heading_error));
    interval_right += (v + omega * half_track) * dt;
    interval_left += (v - omega * half_track) * dt;
    pose = pose * Pose2(v * dt * std::cos(0.5 * omega * dt), v * dt * std::sin(0.5 * omega * dt),
                        omega * dt);
  }
  return run;
}

const ShortOfficeRun& GetShortOfficeRun() {
  static const ShortOfficeRun* run = [] {
    auto* r = new ShortOfficeRun;
    SyntheticRunOptions options;
    options.waypoints = OfficeLoop();
    options.max_duration_s = 36.0;
    options.scan_rate_hz = 10.0;
    options.lidar.num_beams = 271;
    options.lidar.angle_increment_rad = 1.0 * 3.14159265358979 / 180.0;
    options.right_scale_error = 0.03;
    options.left_scale_error = -0.03;
    options.gyro_bias_rad_s = 0.01;
    r->run = MakeSyntheticRun(SegmentWorld::Office(), options);
    r->scans = SyncToScans(r->run.records, ScanSyncOptions{}).scans;
    return r;
  }();
  return *run;
}

const std::vector<Record>& SmallOfficeRecords() {
  static const SyntheticRun* run = [] {
    SyntheticRunOptions options;
    options.waypoints = OfficeLoop();
    options.max_duration_s = 20.0;
    options.scan_rate_hz = 10.0;
    options.lidar.num_beams = 181;
    options.lidar.angle_increment_rad = 1.5 * 3.14159265358979 / 180.0;
    options.right_scale_error = 0.02;
    return new SyntheticRun(MakeSyntheticRun(SegmentWorld::Office(), options));
  }();
  return run->records;
}

double AnchoredPositionRmse(const std::vector<Pose2>& estimate,
                            const std::vector<GroundTruthPose>& truth) {
  const Pose2 anchor = truth.front().map_from_base;
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    sum +=
        ((anchor * estimate[i]).translation() - truth[i].map_from_base.translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(estimate.size()));
}

Stretch FirstTurn(const std::vector<GroundTruthPose>& truth, double min_turn_rad, std::size_t first,
                  std::size_t max_scans) {
  for (std::size_t i = first; i < truth.size(); ++i) {
    for (std::size_t j = i + 1; j < truth.size() && j <= i + max_scans; ++j) {
      const double turn =
          NormalizeAngle(truth[j].map_from_base.theta() - truth[i].map_from_base.theta());
      if (std::abs(turn) > min_turn_rad) return {i, j};
    }
  }
  return {};
}

std::vector<SyncedScan> WithOdometryGap(const std::vector<SyncedScan>& scans, Stretch gap) {
  std::vector<SyncedScan> out;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (i > gap.from && i < gap.to) continue;
    out.push_back(scans[i]);
    if (i == gap.to) {
      out.back().increment = Pose2();
      out.back().odometry_gap_s =
          SecondsBetween(scans[gap.to].scan.time, scans[gap.from].scan.time);
    }
  }
  return out;
}

EndError EndPoseError(const Pose2& last_estimate, const std::vector<GroundTruthPose>& truth) {
  const Pose2 end = truth.front().map_from_base * last_estimate;
  const Pose2& last = truth.back().map_from_base;
  return {(end.translation() - last.translation()).norm(),
          std::abs(NormalizeAngle(end.theta() - last.theta()))};
}

}  // namespace slamrig::slam::testing
