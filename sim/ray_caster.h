#pragma once

#include <box2d/box2d.h>

#include <Eigen/Core>
#include <span>
#include <unordered_map>
#include <vector>

#include "sim/shape_spec.h"

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
/// spinning lidar on a moving robot). The shapes are rasterised nearest first, and a ray whose
/// range is already shorter than the least distance at which a shape could be hit from any of
/// the origins skips the intersection with it (a depth test, as in a z-buffer renderer drawing
/// front to back): a range is the minimum over the shapes it hits, so neither the order nor the
/// skipped tests change a single bit of the result.
///
/// Fixtures listed in `materials` as glass or black return a ray only within kSpecularReturnDeg of
/// their normal; otherwise glass lets it through and black stops it without a return (+infinity,
/// as for no hit). Every other fixture is matte: every ray that reaches it returns.
class RayCaster {
 public:
  /// Caches the shapes of every fixture of `world` except sensors and the fixtures of `ignore`
  /// (the robot itself). Fixtures must not be added or removed afterwards; bodies may move.
  /// Static bodies must stay where they are. `materials` (may be null) is read here only.
  explicit RayCaster(
      b2World* world, const b2Body* ignore = nullptr,
      const std::unordered_map<const b2Fixture*, SurfaceMaterial>* materials = nullptr);

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
    SurfaceMaterial material = SurfaceMaterial::kMatte;
  };
  struct Circle {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double radius = 0.0;
    SurfaceMaterial material = SurfaceMaterial::kMatte;
  };
  struct FixtureShapes {
    const b2Body* body = nullptr;
    bool is_static = false;
    std::vector<Segment> segments;  // world frame if static, else body frame
    std::vector<Circle> circles;
  };
  // A shape in range of the fan, in the world frame, with the distance from the fan's centre.
  struct Candidate {
    double near_m = 0.0;  // no ray of the fan can hit the shape closer than this
    double distance_m = 0.0;
    std::size_t index = 0;  // into segments_ or circles_
    bool circle = false;
  };
  class Query;

  // Adds the segment (world frame) unless no ray of the fan can hit it.
  void AddSegment(const Segment& s, double max_range_m);
  // Adds the circle (world frame) unless no ray of the fan can hit it.
  void AddCircle(const Circle& c, double max_range_m);
  void CastSegment(const Segment& s, const Candidate& candidate, std::span<const Ray> rays,
                   std::span<double> ranges_m);
  void CastCircle(const Circle& c, const Candidate& candidate, std::span<const Ray> rays,
                  std::span<double> ranges_m);
  // Records a hit at `t` of ray `k` on a surface of `material` seen at `cos_incidence` (|cosine|
  // of the angle between the ray and the normal). Only for rays where t < ranges_m[k].
  void Hit(std::size_t k, double t, SurfaceMaterial material, double cos_incidence,
           std::span<double> ranges_m);
  // Calls visit(first, last) for the runs of rays whose angle lies in [lo, hi] modulo 2 pi.
  void ForEachRayInInterval(double lo, double hi, std::size_t num_rays, auto&& visit) const;

  b2World* world_;
  const b2Body* ignore_;
  std::vector<FixtureShapes> fixtures_;
  // Per-Cast scratch.
  std::vector<double> relative_angles_;
  std::vector<const FixtureShapes*> gathered_;
  std::vector<Segment> segments_;      // in range, world frame
  std::vector<Circle> circles_;        // in range, world frame
  std::vector<Candidate> candidates_;  // nearest first
  double first_angle_rad_ = 0.0;
  Eigen::Vector2d center_ = Eigen::Vector2d::Zero();
  double spread_m_ = 0.0;
  long long num_tests_ = 0;
  bool has_materials_ = false;  // some fixture is not matte
  std::vector<char> absorbed_;  // per ray: the nearest hit so far returns nothing
};

}  // namespace slamrig::sim
