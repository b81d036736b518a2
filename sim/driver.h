#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/time.h"

namespace slamrig::sim {

/// A body-frame velocity command: forward speed and yaw rate (REP-103: x forward, CCW positive).
struct VelocityCommand {
  double v_m_s = 0.0;        ///< forward speed, m/s
  double omega_rad_s = 0.0;  ///< yaw rate, rad/s, CCW positive
};

/// One piece of a scripted drive: hold (v, omega) for `duration_s`.
struct ScheduleSegment {
  double duration_s = 1.0;   ///< how long to hold the command, s
  double v_m_s = 0.0;        ///< forward speed, m/s
  double omega_rad_s = 0.0;  ///< yaw rate, rad/s
};

/// How the robot is driven.
enum class DriveMode {
  kIdle,       ///< stand still
  kWaypoints,  ///< pure pursuit along `waypoints_m`
  kSchedule,   ///< a scripted (v, omega) schedule
};

/// Name used in world files ("idle", "waypoints", "schedule").
const char* DriveModeName(DriveMode mode);

/// The autopilot of a simulated run. Pure pursuit steers on the true pose: the driver is part of
/// the scenario, not of the robot under test.
struct DriveOptions {
  DriveMode mode = DriveMode::kIdle;         ///< which of the two drivers, or none
  std::vector<Eigen::Vector2d> waypoints_m;  ///< path in the map frame (waypoints mode)
  bool closed = true;                        ///< the path returns to its first waypoint
  int laps = 1;                              ///< times around a closed path / schedule repeats
  double speed_m_s = 0.5;                    ///< cruise speed (waypoints mode)
  double lookahead_m = 0.6;                  ///< pure pursuit lookahead distance
  double max_yaw_rate_rad_s = 1.0;           ///< the follower slows down to keep within this
  double max_decel_m_s2 = 0.5;               ///< braking before the end of the path
  double goal_tolerance_m = 0.05;            ///< done when this close to the end of the path
  double turn_in_place_rad = 0.8;            ///< turn on the spot while the lookahead point is
                                             ///< further off the heading than this
  /// > 0: where the path doubles back on itself (a dead end), the robot first drives to within
  /// this of the turning point, then turns; 0: pure pursuit alone, which turns back up to half a
  /// lookahead short of it (and may hesitate there, the way back being as near as the way there).
  double dead_end_reach_m = 0.0;
  std::vector<ScheduleSegment> schedule;  ///< schedule mode

  /// One message per broken rule, e.g. "laps = 0; must be >= 1".
  std::vector<std::string> Validate() const;
};

/// Produces velocity commands from DriveOptions: pure pursuit (Coulter, "Implementation of the
/// Pure Pursuit Path Tracking Algorithm", CMU-RI-TR-92-01, 1992: curvature 2 y / L^2 towards the
/// point one lookahead ahead on the path), or a time schedule. Progress along the path only moves
/// forward, so a loop driven N times is followed lap after lap rather than short-cut.
class Driver {
 public:
  /// `options` must be valid (checked).
  explicit Driver(const DriveOptions& options);

  /// The command for time `time` given the robot's true pose in the map frame.
  VelocityCommand Update(Time time, const Pose2& map_from_base);

  /// True once the path (all laps) or the schedule is done; commands are zero from then on.
  bool finished() const { return finished_; }
  /// Completed laps of a closed path (waypoints mode).
  int laps_completed() const;
  /// Distance along the path driven so far (all laps), metres.
  double progress_m() const { return progress_m_; }

 private:
  VelocityCommand FollowPath(const Pose2& map_from_base);
  VelocityCommand FollowSchedule(Time time);
  Eigen::Vector2d PointAt(double s_m) const;
  // Path length of the first dead-end turning point after the progress (beyond end_m_: none).
  double NextReversal() const;

  DriveOptions options_;
  std::vector<Eigen::Vector2d> path_;  // vertices, closing vertex repeated for a closed path
  std::vector<double> cumulative_m_;   // arc length at each vertex
  std::vector<double> reversals_m_;    // arc length of each dead-end vertex within a lap
  double lap_length_m_ = 0.0;
  double end_m_ = 0.0;  // total length to drive
  double progress_m_ = 0.0;
  bool started_ = false;
  Time start_time_;
  bool finished_ = false;
};

}  // namespace slamrig::sim
