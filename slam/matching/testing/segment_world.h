#pragma once

#include <Eigen/Core>
#include <vector>

#include "slam/odometry/gaussian.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam::testing {

/// A wall between two points, world frame.
struct Segment {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
};

/// Beam layout and noise of a simulated planar range finder.
struct RangeFinderSpec {
  int num_beams = 1081;  ///< Hokuyo UTM-30LX
  double angle_min_rad = -0.75 * 3.14159265358979;
  double angle_increment_rad = 0.25 * 3.14159265358979 / 180.0;
  double range_min_m = 0.1;
  double range_max_m = 30.0;
  double range_sigma_m = 0.01;  ///< Gaussian range noise
  Pose2 base_from_laser;
};

/// A world of line segments that casts exact rays: test and benchmark data without the simulator.
class SegmentWorld {
 public:
  explicit SegmentWorld(std::vector<Segment> walls) : walls_(std::move(walls)) {}

  /// An axis-aligned rectangle's four walls, appended.
  void AddBox(double x0, double y0, double x1, double y1);

  /// Range along the ray from `origin` in direction `angle_rad`, or +infinity without a hit.
  double CastRay(const Eigen::Vector2d& origin, double angle_rad) const;

  /// A scan taken at `world_from_base` at time `time`; `rng` adds range noise when not null.
  LaserScan Scan(const Pose2& world_from_base, Time time, const RangeFinderSpec& spec,
                 RandomEngine* rng) const;

  const std::vector<Segment>& walls() const { return walls_; }

  /// An office-like floor: a 20 x 12 m outer wall, rooms along both sides of a corridor loop,
  /// doors, and a few pillars and desks so no corridor is featureless.
  static SegmentWorld Office();

 private:
  std::vector<Segment> walls_;
};

}  // namespace slamrig::slam::testing
