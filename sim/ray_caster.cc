#include "sim/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "slam/types/check.h"

namespace slamrig::sim {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// How far inside a shape's least distance the depth test starts to skip rays, metres: far above
// the rounding of a computed hit distance (1e-13 m; 1e-7 m for a ray grazing a circle), so that a
// skipped test could never have shortened the range.
constexpr double kDepthMargin = 1e-3;
// Bound on the error of CoarseAtan2 (1.15e-5 rad) with room for its rounding, rad.
constexpr double kCoarseAngleError = 2e-5;

Eigen::Vector2d ToEigen(const b2Vec2& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y)};
}

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

struct Transform {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double c = 1.0, s = 0.0;
  Eigen::Vector2d Apply(const Eigen::Vector2d& v) const {
    return {p.x() + c * v.x() - s * v.y(), p.y() + s * v.x() + c * v.y()};
  }
  Eigen::Vector2d Rotate(const Eigen::Vector2d& v) const {
    return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
  }
};

Transform FromB2(const b2Transform& xf) {
  return {ToEigen(xf.p), static_cast<double>(xf.q.c), static_cast<double>(xf.q.s)};
}

// atan2(y, x) within kCoarseAngleError, for the angular bounds of a shape only (they are widened
// by it, so a bound stays conservative and no hit is lost): Abramowitz and Stegun, Handbook of
// Mathematical Functions (1964), Eq. 4.4.49, atan(a) for 0 <= a <= 1 (stated |error| <= 1e-5; with
// the printed coefficients 1.15e-5 at a = 0.396), extended to every octant by symmetry. A fraction
// of the cost of std::atan2.
double CoarseAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double big = std::max(ax, ay);
  if (big == 0.0) return 0.0;
  const double a = std::min(ax, ay) / big;
  const double a2 = a * a;
  double angle =
      a * (0.9998660 + a2 * (-0.3302995 + a2 * (0.1801410 + a2 * (-0.0851330 + a2 * 0.0208351))));
  if (ay > ax) angle = 0.5 * std::numbers::pi - angle;
  if (x < 0.0) angle = std::numbers::pi - angle;
  return std::signbit(y) ? -angle : angle;
}

// Distance from `p` to the segment a + [0, 1] e.
double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& e) {
  const double ee = e.squaredNorm();
  const double f = ee > 0.0 ? std::clamp((p - a).dot(e) / ee, 0.0, 1.0) : 0.0;
  return (a + f * e - p).norm();
}

}  // namespace

// Collects the cached shapes of the fixtures whose broad-phase boxes overlap the query box.
class RayCaster::Query : public b2QueryCallback {
 public:
  Query(const std::vector<FixtureShapes>& fixtures, std::vector<const FixtureShapes*>* out)
      : fixtures_(fixtures), out_(out) {}
  bool ReportFixture(b2Fixture* fixture) override {
    const std::uintptr_t id = fixture->GetUserData().pointer;
    if (id > 0 && id <= fixtures_.size()) out_->push_back(&fixtures_[id - 1]);
    return true;
  }

 private:
  const std::vector<FixtureShapes>& fixtures_;
  std::vector<const FixtureShapes*>* out_;
};

RayCaster::RayCaster(b2World* world, const b2Body* ignore,
                     const std::unordered_map<const b2Fixture*, SurfaceMaterial>* materials)
    : world_(world), ignore_(ignore) {
  for (b2Body* body = world_->GetBodyList(); body != nullptr; body = body->GetNext()) {
    if (body == ignore_) continue;
    const bool is_static = body->GetType() == b2_staticBody;
    const Transform xf = is_static ? FromB2(body->GetTransform()) : Transform{};
    for (b2Fixture* fixture = body->GetFixtureList(); fixture != nullptr;
         fixture = fixture->GetNext()) {
      if (fixture->IsSensor()) continue;
      SurfaceMaterial material = SurfaceMaterial::kMatte;
      if (materials != nullptr) {
        if (const auto it = materials->find(fixture); it != materials->end()) material = it->second;
      }
      has_materials_ = has_materials_ || material != SurfaceMaterial::kMatte;
      FixtureShapes shapes;
      shapes.body = body;
      shapes.is_static = is_static;
      const b2Shape* shape = fixture->GetShape();
      switch (shape->GetType()) {
        case b2Shape::e_polygon: {
          const auto* polygon = static_cast<const b2PolygonShape*>(shape);
          for (int32 i = 0; i < polygon->m_count; ++i) {
            const Eigen::Vector2d a = xf.Apply(ToEigen(polygon->m_vertices[i]));
            const Eigen::Vector2d b =
                xf.Apply(ToEigen(polygon->m_vertices[(i + 1) % polygon->m_count]));
            shapes.segments.push_back(
                {a, b - a, xf.Rotate(ToEigen(polygon->m_normals[i])), true, material});
          }
          break;
        }
        case b2Shape::e_edge: {
          const auto* edge = static_cast<const b2EdgeShape*>(shape);
          const Eigen::Vector2d a = xf.Apply(ToEigen(edge->m_vertex1));
          const Eigen::Vector2d b = xf.Apply(ToEigen(edge->m_vertex2));
          const Eigen::Vector2d e = b - a;
          // Box2D's one-sided edges are solid on the right of vertex1 -> vertex2.
          shapes.segments.push_back(
              {a, e, Eigen::Vector2d(e.y(), -e.x()).normalized(), edge->m_oneSided, material});
          break;
        }
        case b2Shape::e_circle: {
          const auto* circle = static_cast<const b2CircleShape*>(shape);
          shapes.circles.push_back(
              {xf.Apply(ToEigen(circle->m_p)), static_cast<double>(circle->m_radius), material});
          break;
        }
        default:
          SLAMRIG_CHECK(false, "RayCaster supports polygon, edge and circle fixtures only");
      }
      fixtures_.push_back(std::move(shapes));
      fixture->GetUserData().pointer = fixtures_.size();
    }
  }
}

void RayCaster::ForEachRayInInterval(double lo, double hi, std::size_t num_rays,
                                     auto&& visit) const {
  if (hi - lo >= kTwoPi) {
    visit(std::size_t{0}, num_rays);
    return;
  }
  double rel_lo = std::fmod(lo - first_angle_rad_, kTwoPi);
  if (rel_lo < 0.0) rel_lo += kTwoPi;
  const double width = hi - lo;
  const auto begin = relative_angles_.begin(), end = relative_angles_.end();
  // The fan may sweep a little more than a turn (a 360-degree scanner on a turning robot): look
  // for the interval one turn before and after, too. The shifted intervals never overlap.
  for (const double shift : {-kTwoPi, 0.0, kTwoPi}) {
    const double from = rel_lo + shift, to = rel_lo + shift + width;
    if (to < 0.0 || from > relative_angles_.back()) continue;
    const auto first = std::lower_bound(begin, end, from);
    const auto last = std::upper_bound(first, end, to);
    if (first < last) {
      visit(static_cast<std::size_t>(first - begin), static_cast<std::size_t>(last - begin));
    }
  }
}

void RayCaster::AddSegment(const Segment& s, double max_range_m) {
  const double d = DistanceToSegment(center_, s.a, s.e);
  if (d > max_range_m + spread_m_) return;
  // Every origin behind a solid polygon's side: no ray can enter through it.
  if (s.one_sided && (center_ - s.a).dot(s.normal) < -spread_m_) return;
  segments_.push_back(s);
  candidates_.push_back({d - spread_m_ - kDepthMargin, d, segments_.size() - 1, false});
}

void RayCaster::AddCircle(const Circle& c, double max_range_m) {
  const double d = (c.center - center_).norm();
  if (d - c.radius > max_range_m + spread_m_) return;
  circles_.push_back(c);
  candidates_.push_back({d - c.radius - spread_m_ - kDepthMargin, d, circles_.size() - 1, true});
}

void RayCaster::Hit(std::size_t k, double t, SurfaceMaterial material, double cos_incidence,
                    std::span<double> ranges_m) {
  static const double kReturnCos = std::cos(kSpecularReturnDeg * std::numbers::pi / 180.0);
  const bool returns = cos_incidence >= kReturnCos;
  if (!returns && material == SurfaceMaterial::kGlass) return;  // through the glass
  ranges_m[k] = t;
  absorbed_[k] = returns ? 0 : 1;
}

void RayCaster::CastSegment(const Segment& s, const Candidate& candidate, std::span<const Ray> rays,
                            std::span<double> ranges_m) {
  const double d = candidate.distance_m;
  const double near_m = candidate.near_m;
  auto test = [&](std::size_t first, std::size_t last) {
    num_tests_ += static_cast<long long>(last - first);
    for (std::size_t k = first; k < last; ++k) {
      if (ranges_m[k] <= near_m) continue;  // depth test: a nearer shape already hides it
      const Ray& ray = rays[k];
      const double denom = Cross(ray.direction, s.e);
      if (denom == 0.0) continue;
      if (s.one_sided && ray.direction.dot(s.normal) >= 0.0) continue;
      const Eigen::Vector2d w = s.a - ray.origin;
      const double t = Cross(w, s.e) / denom;
      if (t < 0.0 || t >= ranges_m[k]) continue;
      const double u = Cross(w, ray.direction) / denom;
      if (u < 0.0 || u > 1.0) continue;
      if (s.material == SurfaceMaterial::kMatte) {
        ranges_m[k] = t;
        if (has_materials_) absorbed_[k] = 0;
      } else {
        Hit(k, t, s.material, std::abs(ray.direction.dot(s.normal)), ranges_m);
      }
    }
  };
  const double x = spread_m_ / d;
  if (x > 0.99) {
    test(0, rays.size());
    return;
  }
  // The angles under which the segment is seen from the centre, widened by the most the view can
  // turn from another origin within the spread: asin(spread / d) <= tan(asin(spread / d)).
  const Eigen::Vector2d pa = s.a - center_, pb = pa + s.e;
  // (Each of the two coarse angles is off by at most kCoarseAngleError, so are both ends.)
  const double phi_a = CoarseAtan2(pa.y(), pa.x());
  const double delta = CoarseAtan2(Cross(pa, pb), pa.dot(pb));
  const double lo = phi_a + std::min(0.0, delta);
  const double widen = x / std::sqrt(1.0 - x * x) + 2.0 * kCoarseAngleError;
  ForEachRayInInterval(lo - widen, lo + std::abs(delta) + widen, rays.size(), test);
}

void RayCaster::CastCircle(const Circle& c, const Candidate& candidate, std::span<const Ray> rays,
                           std::span<double> ranges_m) {
  const Eigen::Vector2d pc = c.center - center_;
  const double d = candidate.distance_m;
  const double near_m = candidate.near_m;
  const double r2 = c.radius * c.radius;
  auto test = [&](std::size_t first, std::size_t last) {
    num_tests_ += static_cast<long long>(last - first);
    for (std::size_t k = first; k < last; ++k) {
      if (ranges_m[k] <= near_m) continue;  // depth test: a nearer shape already hides it
      const Ray& ray = rays[k];
      const Eigen::Vector2d w = ray.origin - c.center;
      const double b = w.dot(ray.direction);
      const double disc = b * b - (w.squaredNorm() - r2);
      if (disc < 0.0) continue;
      // The entry point; negative when the ray starts inside (no hit, as in Box2D).
      const double t = -b - std::sqrt(disc);
      if (t < 0.0 || t >= ranges_m[k]) continue;
      if (c.material == SurfaceMaterial::kMatte) {
        ranges_m[k] = t;
        if (has_materials_) absorbed_[k] = 0;
      } else {
        // The normal at the entry point is (w + t d) / r; its cosine with d is (b + t) / r.
        Hit(k, t, c.material, std::abs(b + t) / c.radius, ranges_m);
      }
    }
  };
  if (d <= (c.radius + spread_m_) * 1.01) {
    test(0, rays.size());
    return;
  }
  // Half-angle of the disc seen from the nearest origin, plus the turn of the centre's bearing.
  const double x1 = c.radius / (d - spread_m_), x2 = spread_m_ / d;
  const double half =
      x1 / std::sqrt(1.0 - x1 * x1) + x2 / std::sqrt(1.0 - x2 * x2) + kCoarseAngleError;
  const double phi = CoarseAtan2(pc.y(), pc.x());
  ForEachRayInInterval(phi - half, phi + half, rays.size(), test);
}

void RayCaster::Cast(std::span<const Ray> rays, double max_range_m, std::span<double> ranges_m) {
  SLAMRIG_CHECK(rays.size() == ranges_m.size(), "one range per ray");
  std::fill(ranges_m.begin(), ranges_m.end(), kInfinity);
  num_tests_ = 0;
  if (rays.empty()) return;
  if (has_materials_) absorbed_.assign(rays.size(), 0);

  // The origins' bounding circle.
  Eigen::Vector2d lo = rays.front().origin, hi = rays.front().origin;
  for (const Ray& ray : rays) {
    lo = lo.cwiseMin(ray.origin);
    hi = hi.cwiseMax(ray.origin);
  }
  center_ = 0.5 * (lo + hi);
  spread_m_ = 0.5 * (hi - lo).norm() + 1e-9;

  first_angle_rad_ = rays.front().angle_rad;
  relative_angles_.resize(rays.size());
  for (std::size_t k = 0; k < rays.size(); ++k) {
    relative_angles_[k] = rays[k].angle_rad - rays.front().angle_rad;
  }
  SLAMRIG_CHECK(relative_angles_.back() < 2.0 * kTwoPi, "a fan spans less than two turns");

  // Gather the fixtures in range through the broad phase, and their shapes in the world frame.
  gathered_.clear();
  Query query(fixtures_, &gathered_);
  const double reach = max_range_m + spread_m_;
  b2AABB box;
  box.lowerBound =
      b2Vec2(static_cast<float>(center_.x() - reach), static_cast<float>(center_.y() - reach));
  box.upperBound =
      b2Vec2(static_cast<float>(center_.x() + reach), static_cast<float>(center_.y() + reach));
  world_->QueryAABB(&query, box);
  segments_.clear();
  circles_.clear();
  candidates_.clear();
  for (const FixtureShapes* shapes : gathered_) {
    if (shapes->body == ignore_) continue;
    if (shapes->is_static) {
      for (const Segment& s : shapes->segments) AddSegment(s, max_range_m);
      for (const Circle& c : shapes->circles) AddCircle(c, max_range_m);
    } else {
      const Transform xf = FromB2(shapes->body->GetTransform());
      for (const Segment& s : shapes->segments) {
        AddSegment({xf.Apply(s.a), xf.Rotate(s.e), xf.Rotate(s.normal), s.one_sided, s.material},
                   max_range_m);
      }
      for (const Circle& c : shapes->circles)
        AddCircle({xf.Apply(c.center), c.radius, c.material}, max_range_m);
    }
  }

  // Nearest first, so that the depth test skips most of the shapes hidden behind others.
  std::sort(candidates_.begin(), candidates_.end(),
            [](const Candidate& a, const Candidate& b) { return a.near_m < b.near_m; });
  for (const Candidate& candidate : candidates_) {
    if (candidate.circle) {
      CastCircle(circles_[candidate.index], candidate, rays, ranges_m);
    } else {
      CastSegment(segments_[candidate.index], candidate, rays, ranges_m);
    }
  }
  for (double& range : ranges_m) {
    if (range > max_range_m) range = kInfinity;
  }
  if (has_materials_) {
    for (std::size_t k = 0; k < rays.size(); ++k) {
      if (absorbed_[k] != 0) ranges_m[k] = kInfinity;
    }
  }
}

}  // namespace slamrig::sim
