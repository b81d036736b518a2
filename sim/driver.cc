#include "sim/driver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::sim {

const char* DriveModeName(DriveMode mode) {
  switch (mode) {
    case DriveMode::kIdle:
      return "idle";
    case DriveMode::kWaypoints:
      return "waypoints";
    case DriveMode::kSchedule:
      return "schedule";
  }
  return "?";
}

std::vector<std::string> DriveOptions::Validate() const {
  Rules rules;
  rules.AtLeast("laps", laps, 1);
  if (mode == DriveMode::kWaypoints) {
    rules.Positive("speed_m_s", speed_m_s)
        .Positive("lookahead_m", lookahead_m)
        .Positive("max_yaw_rate_rad_s", max_yaw_rate_rad_s)
        .Positive("max_decel_m_s2", max_decel_m_s2)
        .Positive("goal_tolerance_m", goal_tolerance_m)
        .NonNegative("dead_end_reach_m", dead_end_reach_m)
        .Require(turn_in_place_rad > 0.0 && turn_in_place_rad <= std::numbers::pi,
                 "turn_in_place_rad", turn_in_place_rad, "must be in (0, pi]");
    if (waypoints_m.size() < 2) {
      rules.Add("waypoints_m has " + std::to_string(waypoints_m.size()) +
                " points; pure pursuit needs at least 2");
    }
    for (std::size_t i = 0; i + 1 < waypoints_m.size(); ++i) {
      if ((waypoints_m[i + 1] - waypoints_m[i]).norm() < 1e-3) {
        rules.Add("waypoints_m[" + std::to_string(i + 1) + "] repeats the point before it");
      }
    }
    rules.Require(closed || laps == 1, "laps", laps, "an open path (closed: false) has 1");
  }
  if (mode == DriveMode::kSchedule) {
    if (schedule.empty()) rules.Add("schedule is empty; schedule mode needs segments");
    for (std::size_t i = 0; i < schedule.size(); ++i) {
      rules.Positive("schedule[" + std::to_string(i) + "].duration_s", schedule[i].duration_s);
    }
  }
  return rules.errors();
}

Driver::Driver(const DriveOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "DriveOptions");
  if (options_.mode != DriveMode::kWaypoints) return;
  path_ = options_.waypoints_m;
  if (options_.closed) path_.push_back(path_.front());
  cumulative_m_.assign(path_.size(), 0.0);
  for (std::size_t i = 1; i < path_.size(); ++i) {
    cumulative_m_[i] = cumulative_m_[i - 1] + (path_[i] - path_[i - 1]).norm();
  }
  lap_length_m_ = cumulative_m_.back();
  end_m_ = lap_length_m_ * options_.laps;
  if (options_.dead_end_reach_m > 0.0) {
    const std::size_t n = path_.size();
    for (std::size_t j = 1; j < n; ++j) {
      if (j + 1 == n && !options_.closed) break;
      const Eigen::Vector2d u = path_[j] - path_[j - 1];
      const Eigen::Vector2d w = j + 1 < n ? path_[j + 1] - path_[j] : path_[1] - path_[0];
      const double cross = u.x() * w.y() - u.y() * w.x();
      if (u.dot(w) < 0.0 && std::abs(cross) <= 1e-9 * u.norm() * w.norm()) {
        reversals_m_.push_back(cumulative_m_[j]);
      }
    }
  }
}

double Driver::NextReversal() const {
  if (reversals_m_.empty()) return std::numeric_limits<double>::infinity();
  const int lap = static_cast<int>(std::floor(progress_m_ / lap_length_m_));
  for (int k = lap; k <= lap + 1; ++k) {
    for (const double s : reversals_m_) {
      if (k * lap_length_m_ + s > progress_m_) return k * lap_length_m_ + s;
    }
  }
  return std::numeric_limits<double>::infinity();
}

int Driver::laps_completed() const {
  if (options_.mode != DriveMode::kWaypoints || lap_length_m_ <= 0.0) return 0;
  if (finished_) return options_.laps;
  return static_cast<int>(std::floor(progress_m_ / lap_length_m_));
}

Eigen::Vector2d Driver::PointAt(double s_m) const {
  double s = std::clamp(s_m, 0.0, end_m_);
  if (options_.closed) s = std::fmod(s, lap_length_m_);
  const auto it = std::upper_bound(cumulative_m_.begin(), cumulative_m_.end(), s);
  const std::size_t j = std::clamp<std::size_t>(
      static_cast<std::size_t>(it - cumulative_m_.begin()), 1, path_.size() - 1);
  const double length = cumulative_m_[j] - cumulative_m_[j - 1];
  const double f = std::clamp((s - cumulative_m_[j - 1]) / length, 0.0, 1.0);
  return path_[j - 1] + f * (path_[j] - path_[j - 1]);
}

VelocityCommand Driver::Update(Time time, const Pose2& map_from_base) {
  if (finished_) return {};
  switch (options_.mode) {
    case DriveMode::kIdle:
      return {};
    case DriveMode::kWaypoints:
      return FollowPath(map_from_base);
    case DriveMode::kSchedule:
      return FollowSchedule(time);
  }
  return {};
}

VelocityCommand Driver::FollowSchedule(Time time) {
  if (!started_) {
    started_ = true;
    start_time_ = time;
  }
  double elapsed = SecondsBetween(time, start_time_);
  for (int lap = 0; lap < options_.laps; ++lap) {
    for (const auto& segment : options_.schedule) {
      if (elapsed < segment.duration_s) return {segment.v_m_s, segment.omega_rad_s};
      elapsed -= segment.duration_s;
    }
  }
  finished_ = true;
  return {};
}

VelocityCommand Driver::FollowPath(const Pose2& map_from_base) {
  const Eigen::Vector2d position = map_from_base.translation();
  // Project onto the path within a window ahead of the current progress (never behind it by more
  // than a little, so a loop is not short-cut where the path passes near itself).
  // At a dead end the way back lies on the way there: progress may pass the turning point only
  // once the robot has reached it.
  double reversal = NextReversal();
  if (reversal <= end_m_ && (PointAt(reversal) - position).norm() <= options_.dead_end_reach_m) {
    progress_m_ = reversal;
    reversal = NextReversal();
  }
  const double window_lo = std::max(0.0, progress_m_ - 0.25);
  const double window_hi =
      std::min({end_m_, progress_m_ + std::max(2.0 * options_.lookahead_m, 1.0), reversal});
  double best_s = progress_m_;
  double best_d2 = std::numeric_limits<double>::infinity();
  const int first_lap = static_cast<int>(std::floor(window_lo / lap_length_m_));
  const int last_lap = std::min(options_.laps - 1, static_cast<int>(window_hi / lap_length_m_));
  for (int lap = first_lap; lap <= last_lap; ++lap) {
    const double lap_start = lap * lap_length_m_;
    for (std::size_t j = 1; j < path_.size(); ++j) {
      const double s0 = lap_start + cumulative_m_[j - 1];
      const double s1 = lap_start + cumulative_m_[j];
      if (s1 < window_lo || s0 > window_hi) continue;
      const Eigen::Vector2d a = path_[j - 1], ab = path_[j] - path_[j - 1];
      double f = std::clamp((position - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      const double s = std::clamp(s0 + f * (s1 - s0), window_lo, window_hi);
      f = (s - s0) / (s1 - s0);
      const double d2 = (a + f * ab - position).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best_s = s;
      }
    }
  }
  progress_m_ = std::max(progress_m_, best_s);
  const double remaining_m = end_m_ - progress_m_;
  const Eigen::Vector2d goal = PointAt(end_m_);
  // Done at the end of the path, or once the end is near and already behind the robot.
  const Pose2 base_from_map = map_from_base.Inverse();
  if (remaining_m <= options_.goal_tolerance_m ||
      (remaining_m < options_.lookahead_m && (base_from_map * goal).x() <= 0.0)) {
    finished_ = true;
    progress_m_ = end_m_;
    return {};
  }

  // Lookahead point in the robot frame.
  const Eigen::Vector2d target = PointAt(std::min(progress_m_ + options_.lookahead_m, reversal));
  const Eigen::Vector2d local = base_from_map * target;
  const double dist2 = std::max(local.squaredNorm(), 1e-9);
  const double bearing = std::atan2(local.y(), local.x());
  if (std::abs(bearing) > options_.turn_in_place_rad) {
    // Far off the heading: turn on the spot towards it (a skid-steer robot cannot follow a
    // tight arc, and cutting a corner through a door catches the frame).
    return {0.0, std::copysign(0.5 * options_.max_yaw_rate_rad_s, bearing)};
  }
  const double curvature = 2.0 * local.y() / dist2;
  double v = options_.speed_m_s;
  if (std::abs(curvature) > 1e-9)
    v = std::min(v, options_.max_yaw_rate_rad_s / std::abs(curvature));
  const double to_goal_m = std::max(remaining_m, (goal - position).norm());
  v = std::min(v, std::sqrt(2.0 * options_.max_decel_m_s2 * to_goal_m));
  return {v, v * curvature};
}

}  // namespace slamrig::sim
