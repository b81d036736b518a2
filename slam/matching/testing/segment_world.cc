#include "slam/matching/testing/segment_world.h"

#include <cmath>
#include <limits>

namespace slamrig::slam::testing {

void SegmentWorld::AddBox(double x0, double y0, double x1, double y1) {
  walls_.push_back({{x0, y0}, {x1, y0}});
  walls_.push_back({{x1, y0}, {x1, y1}});
  walls_.push_back({{x1, y1}, {x0, y1}});
  walls_.push_back({{x0, y1}, {x0, y0}});
}

double SegmentWorld::CastRay(const Eigen::Vector2d& origin, double angle_rad) const {
  const Eigen::Vector2d d(std::cos(angle_rad), std::sin(angle_rad));
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& w : walls_) {
    // Solve origin + t d = a + u (b - a), t >= 0, u in [0, 1].
    const Eigen::Vector2d e = w.b - w.a;
    const double denom = d.x() * e.y() - d.y() * e.x();
    if (std::abs(denom) < 1e-12) continue;
    const Eigen::Vector2d f = w.a - origin;
    const double t = (f.x() * e.y() - f.y() * e.x()) / denom;
    const double u = (f.x() * d.y() - f.y() * d.x()) / denom;
    if (t > 1e-9 && u >= 0.0 && u <= 1.0 && t < best) best = t;
  }
  return best;
}

LaserScan SegmentWorld::Scan(const Pose2& world_from_base, Time time, const RangeFinderSpec& spec,
                             RandomEngine* rng) const {
  LaserScan scan;
  scan.time = time;
  scan.angle_min_rad = spec.angle_min_rad;
  scan.angle_increment_rad = spec.angle_increment_rad;
  scan.range_min_m = spec.range_min_m;
  scan.range_max_m = spec.range_max_m;
  scan.base_from_laser = spec.base_from_laser;
  scan.ranges_m.resize(static_cast<std::size_t>(spec.num_beams));
  const Pose2 world_from_laser = world_from_base * spec.base_from_laser;
  for (int i = 0; i < spec.num_beams; ++i) {
    double r = CastRay(world_from_laser.translation(),
                       world_from_laser.theta() + scan.BeamAngle(static_cast<std::size_t>(i)));
    if (rng != nullptr && std::isfinite(r)) r += spec.range_sigma_m * StandardNormal(*rng);
    if (!(r < spec.range_max_m)) r = spec.range_max_m;  // no return
    scan.ranges_m[static_cast<std::size_t>(i)] = static_cast<float>(r);
  }
  return scan;
}

SegmentWorld SegmentWorld::Office() {
  SegmentWorld world({});
  world.AddBox(0.0, 0.0, 20.0, 12.0);
  // Inner block ringed by the corridor loop (corridor ~2 m wide), with rooms inside it.
  const double x0 = 3.0, y0 = 3.0, x1 = 17.0, y1 = 9.0;
  // Inner block walls with door gaps.
  world.walls_.push_back({{x0, y0}, {7.0, y0}});
  world.walls_.push_back({{8.0, y0}, {x1, y0}});
  world.walls_.push_back({{x1, y0}, {x1, y1}});
  world.walls_.push_back({{x1, y1}, {12.0, y1}});
  world.walls_.push_back({{11.0, y1}, {x0, y1}});
  world.walls_.push_back({{x0, y1}, {x0, y0}});
  world.walls_.push_back({{10.0, y0}, {10.0, y1}});  // splits the block into two rooms
  // Rooms along the outer wall: partition walls stick into the corridor's outer side.
  for (double x : {5.0, 9.5, 14.0}) {
    world.walls_.push_back({{x, 0.0}, {x, 1.0}});
    world.walls_.push_back({{x, 12.0}, {x, 11.0}});
  }
  world.walls_.push_back({{0.0, 6.0}, {1.0, 6.0}});
  world.walls_.push_back({{20.0, 5.0}, {19.0, 5.0}});
  // Pillars and desks.
  world.AddBox(1.2, 8.5, 1.6, 8.9);
  world.AddBox(18.3, 2.0, 18.7, 2.4);
  world.AddBox(4.0, 4.0, 5.5, 4.8);
  world.AddBox(13.0, 6.5, 14.5, 7.0);
  world.AddBox(6.5, 10.6, 7.0, 11.1);
  return world;
}

}  // namespace slamrig::slam::testing
