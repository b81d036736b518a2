#pragma once

#include <box2d/box2d.h>

#include <Eigen/Core>
#include <span>
#include <vector>

namespace slamrig::sim {

/// One ray of a fan, in the map frame.
struct Ray {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();      ///< start point
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  ///< unit vector
  double angle_rad = 0.0;  ///< atan2 of `direction` plus any multiple of 2 pi (see Cast)
};

/// Casts fans of rays against the fixtures of a Box2D world, analytically and fast, with the hit
/// semantics of b2World::RayCast: solid polygons and circles are hit where a ray enters them (a
/// ray starting inside one does not hit it), edges are hit from either side.
///
/// Per fan the fixtures in range are gathered once through Box2D's broad phase; then each edge
/// and circle is rasterised over the beam angles it can cover, seen from the fan's origins, into a
/// per-ray depth buffer; every ray it covers gets an exact ray-segment or ray-circle intersection.
/// So each ray only meets the few edges near its direction, and rays may each start elsewhere (a
/// spinning lidar on a moving robot).
class RayCaster {
 public:
  /// Caches the shapes of every fixture of `world` except sensors and the fixtures of `ignore`
  /// (the robot itself). Fixtures must not be added or removed afterwards; bodies may move.
  /// Static bodies must stay where they are.
  explicit RayCaster(b2World* world, const b2Body* ignore = nullptr);

  /// Writes the distance along each ray to the first surface, or +infinity when there is none
  /// within `max_range_m`, into `ranges_m` (same size as `rays`). The rays' `angle_rad` must be
  /// non-decreasing and span less than 4 pi: one sweep of a scanner (which may overlap itself).
  void Cast(std::span<const Ray> rays, double max_range_m, std::span<double> ranges_m);

  /// Ray-versus-shape intersection tests done by the last Cast (for benchmarks and tests).
  long long last_num_tests() const { return num_tests_; }

 private:
  struct Segment {
    Eigen::Vector2d a = Eigen::Vector2d::Zero();       // start
    Eigen::Vector2d e = Eigen::Vector2d::Zero();       // end - start
    Eigen::Vector2d normal = Eigen::Vector2d::Zero();  // outward unit normal of a polygon side
    bool one_sided = false;  // hit only when entering through the normal's side
  };
  struct Circle {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double radius = 0.0;
  };
  struct FixtureShapes {
    const b2Body* body = nullptr;
    bool is_static = false;
    std::vector<Segment> segments;  // world frame if static, else body frame
    std::vector<Circle> circles;
  };
  class Query;

  void CastSegment(const Segment& s, double max_range_m, std::span<const Ray> rays,
                   std::span<double> ranges_m);
  void CastCircle(const Circle& c, double max_range_m, std::span<const Ray> rays,
                  std::span<double> ranges_m);
  // Calls visit(first, last) for the runs of rays whose angle lies in [lo, hi] modulo 2 pi.
  void ForEachRayInInterval(double lo, double hi, std::size_t num_rays, auto&& visit) const;

  b2World* world_;
  const b2Body* ignore_;
  std::vector<FixtureShapes> fixtures_;
  // Per-Cast scratch.
  std::vector<double> relative_angles_;
  std::vector<const FixtureShapes*> gathered_;
  double first_angle_rad_ = 0.0;
  Eigen::Vector2d center_ = Eigen::Vector2d::Zero();
  double spread_m_ = 0.0;
  long long num_tests_ = 0;
};

}  // namespace slamrig::sim
