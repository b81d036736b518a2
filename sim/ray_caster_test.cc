#include "sim/ray_caster.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <unordered_map>
#include <vector>

#include "slam/types/random_stream.h"

namespace slamrig::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxRange = 30.0;

// Box2D's own answer: the closest fixture along the segment, ignoring `ignore`'s fixtures.
class ClosestHit : public b2RayCastCallback {
 public:
  explicit ClosestHit(const b2Body* ignore) : ignore_(ignore) {}
  float ReportFixture(b2Fixture* fixture, const b2Vec2&, const b2Vec2& normal,
                      float fraction) override {
    if (fixture->GetBody() == ignore_) return -1.0f;
    fraction_ = fraction;
    fixture_ = fixture;
    normal_ = normal;
    return fraction;
  }
  float fraction_ = -1.0f;
  const b2Fixture* fixture_ = nullptr;
  b2Vec2 normal_{0.0f, 0.0f};

 private:
  const b2Body* ignore_;
};

double Box2dRange(const b2World& world, const Ray& ray, const b2Body* ignore,
                  const b2Fixture** hit_fixture = nullptr, double* incidence_cos = nullptr) {
  ClosestHit hit(ignore);
  const Eigen::Vector2d end = ray.origin + kMaxRange * ray.direction;
  world.RayCast(&hit,
                b2Vec2(static_cast<float>(ray.origin.x()), static_cast<float>(ray.origin.y())),
                b2Vec2(static_cast<float>(end.x()), static_cast<float>(end.y())));
  if (hit_fixture != nullptr) *hit_fixture = hit.fixture_;
  if (incidence_cos != nullptr) {
    *incidence_cos =
        std::abs(hit.normal_.x * ray.direction.x() + hit.normal_.y * ray.direction.y());
  }
  return hit.fraction_ < 0.0f ? kInf : hit.fraction_ * kMaxRange;
}

// A world of random boxes, convex polygons, circles and two-sided edges, some of them on a moved
// kinematic body, and a "robot" body the caster must ignore.
struct RandomWorld {
  b2World world{b2Vec2(0.0f, 0.0f)};
  b2Body* robot = nullptr;
  std::vector<Eigen::Vector2d> vertices;  // every corner, for grazing rays
  std::vector<std::pair<Eigen::Vector2d, double>> circles;

  explicit RandomWorld(std::uint64_t seed) {
    RandomStream rng(seed, "world");
    auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.Uniform(); };
    b2BodyDef static_def;
    b2Body* ground = world.CreateBody(&static_def);
    b2BodyDef kinematic_def;
    kinematic_def.type = b2_kinematicBody;
    kinematic_def.position.Set(3.0f, -2.0f);
    kinematic_def.angle = 0.7f;
    b2Body* mover = world.CreateBody(&kinematic_def);
    b2BodyDef robot_def;
    robot_def.type = b2_dynamicBody;
    robot_def.position.Set(10.0f, 10.0f);
    robot = world.CreateBody(&robot_def);
    b2PolygonShape robot_box;
    robot_box.SetAsBox(0.3f, 0.25f);
    robot->CreateFixture(&robot_box, 1.0f);

    for (int i = 0; i < 60; ++i) {
      b2Body* body = i % 5 == 0 ? mover : ground;
      const b2Transform xf = body->GetTransform();
      // Every pair or triple of draws here is sequenced, the last argument first: the order the
      // scenes were generated in (a call's arguments are drawn in the compiler's order).
      const auto cy = static_cast<float>(uniform(0, 20));
      const b2Vec2 c(static_cast<float>(uniform(0, 20)), cy);
      switch (i % 4) {
        case 0: {
          b2PolygonShape box;
          const auto angle = static_cast<float>(uniform(-3, 3));
          const auto hy = static_cast<float>(uniform(0.05, 1.5));
          box.SetAsBox(static_cast<float>(uniform(0.05, 1.5)), hy, c, angle);
          body->CreateFixture(&box, 1.0f);
          for (int k = 0; k < box.m_count; ++k) vertices.push_back(World(xf, box.m_vertices[k]));
          break;
        }
        case 1: {
          std::vector<b2Vec2> points;
          const int n = 3 + static_cast<int>(uniform(0, 6));
          for (int k = 0; k < n; ++k) {
            const double a = 2.0 * std::numbers::pi * k / n + uniform(0, 0.5);
            const double r = uniform(0.3, 1.2);
            points.emplace_back(c.x + static_cast<float>(r * std::cos(a)),
                                c.y + static_cast<float>(r * std::sin(a)));
          }
          b2PolygonShape polygon;
          polygon.Set(points.data(), n);
          body->CreateFixture(&polygon, 1.0f);
          for (int k = 0; k < polygon.m_count; ++k)
            vertices.push_back(World(xf, polygon.m_vertices[k]));
          break;
        }
        case 2: {
          b2CircleShape circle;
          circle.m_p = c;
          circle.m_radius = static_cast<float>(uniform(0.05, 1.0));
          body->CreateFixture(&circle, 1.0f);
          circles.push_back({World(xf, c), circle.m_radius});
          break;
        }
        default: {
          b2EdgeShape edge;
          const auto dy = static_cast<float>(uniform(-3, 3));
          const b2Vec2 d(static_cast<float>(uniform(-3, 3)), dy);
          edge.SetTwoSided(c, c + d);
          body->CreateFixture(&edge, 0.0f);
          vertices.push_back(World(xf, c));
          vertices.push_back(World(xf, c + d));
        }
      }
    }
  }

  static Eigen::Vector2d World(const b2Transform& xf, const b2Vec2& v) {
    const b2Vec2 w = b2Mul(xf, v);
    return {w.x, w.y};
  }

  // True if the ray's line passes within `tol` of a corner or touches a circle tangentially.
  bool Grazes(const Ray& ray, double tol) const {
    auto line_distance = [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d d = p - ray.origin;
      return std::abs(d.x() * ray.direction.y() - d.y() * ray.direction.x());
    };
    for (const auto& v : vertices) {
      if (line_distance(v) < tol) return true;
    }
    for (const auto& [center, radius] : circles) {
      if (std::abs(line_distance(center) - radius) < tol) return true;
    }
    return false;
  }
};

// A lidar-like fan: `n` rays over `fov` rad, the origin moving by `motion` and the heading turning
// by `turn` from the first ray to the last.
std::vector<Ray> Fan(const Eigen::Vector2d& origin, double heading, double fov, int n,
                     const Eigen::Vector2d& motion, double turn) {
  std::vector<Ray> rays(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double f = static_cast<double>(i) / (n - 1);
    const double angle = heading - 0.5 * fov + f * (fov + turn);
    // Box2D takes float end points: cast exactly the ray it sees, from the rounded origin to the
    // rounded end point at max range.
    const Eigen::Vector2d o = origin + f * motion;
    const Eigen::Vector2d start = o.cast<float>().cast<double>();
    const Eigen::Vector2d end = (o + kMaxRange * Eigen::Vector2d(std::cos(angle), std::sin(angle)))
                                    .cast<float>()
                                    .cast<double>();
    const Eigen::Vector2d d = (end - start).normalized();
    rays[static_cast<std::size_t>(i)] = {
        start, d, angle + std::remainder(std::atan2(d.y(), d.x()) - angle, 2.0 * std::numbers::pi)};
  }
  return rays;
}

TEST(RayCasterTest, HitsABoxWallAtItsFace) {
  b2World world(b2Vec2(0.0f, 0.0f));
  b2BodyDef def;
  b2Body* ground = world.CreateBody(&def);
  b2PolygonShape box;
  box.SetAsBox(0.1f, 5.0f, b2Vec2(4.0f, 0.0f), 0.0f);
  ground->CreateFixture(&box, 0.0f);
  RayCaster caster(&world);
  const std::vector<Ray> rays = {
      {{0.0, 0.0}, {1.0, 0.0}, 0.0},
      {{0.0, 0.0}, {std::sqrt(0.5), std::sqrt(0.5)}, std::numbers::pi / 4},
      {{0.0, 0.0}, {0.0, 1.0}, std::numbers::pi / 2}};
  std::vector<double> ranges(rays.size());
  caster.Cast(rays, 30.0, ranges);
  EXPECT_NEAR(ranges[0], 3.9, 1e-6);
  EXPECT_NEAR(ranges[1], 3.9 * std::sqrt(2.0), 1e-6);
  EXPECT_EQ(ranges[2], kInf);
}

// Box2D intersects a circle in float through c^2 - |r|^2 b, which cancels badly for a 30 m ray:
// for circles the exact (double) intersection is the reference, and Box2D must lie within its own
// rounding bound of it. Returns the exact range.
double ExactCircleRange(const b2Fixture* fixture, const Ray& ray, double* box2d_bound_m) {
  const auto* circle = static_cast<const b2CircleShape*>(fixture->GetShape());
  const b2Vec2 center = b2Mul(fixture->GetBody()->GetTransform(), circle->m_p);
  const Eigen::Vector2d s = ray.origin - Eigen::Vector2d(center.x, center.y);
  const double radius = circle->m_radius;
  const double b = s.dot(ray.direction);
  const double c = b * kMaxRange, rr = kMaxRange * kMaxRange;
  const double sigma = c * c - rr * (s.squaredNorm() - radius * radius);
  *box2d_bound_m = 8.0 * 0x1.0p-24 * (c * c + rr * s.squaredNorm()) /
                       (2.0 * std::sqrt(std::max(sigma, 1e-12)) * rr) * kMaxRange +
                   1e-4;
  return -b - std::sqrt(b * b - (s.squaredNorm() - radius * radius));
}

// (sx * u, sy * v) for two uniform draws u, v; v is drawn first, the order the cases here were
// generated in (the arguments of one call are drawn in the compiler's order).
Eigen::Vector2d RandomPoint(RandomStream& rng, double sx, double sy) {
  const double y = sy * rng.Uniform();
  return {sx * rng.Uniform(), y};
}

TEST(RayCasterTest, AgreesWithBox2dRayCastOnRandomWorlds) {
  int rays = 0, hits = 0, grazing_corners = 0, grazing_incidence = 0, circle_hits = 0;
  double max_difference_m = 0.0, max_circle_error_m = 0.0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    RandomWorld w(seed);
    RayCaster caster(&w.world, w.robot);
    RandomStream rng(seed, "origins");
    for (int trial = 0; trial < 12; ++trial) {
      const Eigen::Vector2d origin = RandomPoint(rng, 20.0, 20.0);
      const double heading = 2.0 * std::numbers::pi * rng.Uniform();
      // Half the fans sweep from a fixed origin, half from a moving, turning one.
      const bool moving = trial % 2 == 1;
      const Eigen::Vector2d motion = moving ? RandomPoint(rng, 0.3, -0.2) : Eigen::Vector2d::Zero();
      const double turn = moving ? 0.02 * rng.Uniform() : 0.0;
      const double fov = trial % 4 < 2 ? 1.5 * std::numbers::pi : 1.98 * std::numbers::pi;
      const auto fan = Fan(origin, heading, fov, 1081, motion, turn);
      std::vector<double> ranges(fan.size());
      caster.Cast(fan, kMaxRange, ranges);
      for (std::size_t i = 0; i < fan.size(); ++i) {
        const b2Fixture* fixture = nullptr;
        double incidence_cos = 1.0;
        const double expected = Box2dRange(w.world, fan[i], w.robot, &fixture, &incidence_cos);
        ++rays;
        if (expected == kInf && ranges[i] == kInf) continue;
        ++hits;
        const double difference = std::abs(expected - ranges[i]);
        if (difference > 1e-4 && w.Grazes(fan[i], 1e-4)) {
          ++grazing_corners;  // float and double may see a corner on either side
          continue;
        }
        ASSERT_NE(fixture, nullptr) << "caster hit " << ranges[i] << " where Box2D saw nothing";
        if (fixture->GetType() == b2Shape::e_circle) {
          ++circle_hits;
          double box2d_bound_m = 0.0;
          const double exact = ExactCircleRange(fixture, fan[i], &box2d_bound_m);
          max_circle_error_m = std::max(max_circle_error_m, std::abs(ranges[i] - exact));
          EXPECT_NEAR(ranges[i], exact, 1e-4);
          EXPECT_NEAR(expected, exact, box2d_bound_m);
          continue;
        }
        if (incidence_cos < 0.05) {
          // Within 3 degrees of grazing, Box2D's float rounding (~1e-6 m) is amplified 20x+.
          ++grazing_incidence;
          EXPECT_LE(difference * incidence_cos, 2e-6) << "seed " << seed << " ray " << i;
          continue;
        }
        max_difference_m = std::max(max_difference_m, difference);
        EXPECT_LE(difference, 1e-4)
            << "seed " << seed << " trial " << trial << " ray " << i << ": caster " << ranges[i]
            << " vs b2World::RayCast " << expected;
      }
    }
  }
  std::printf(
      "%d rays, %d hits: polygons and edges max |caster - b2World::RayCast| = %.3g m (%d hits "
      "within 3 deg of grazing excluded); circles max |caster - exact| = %.3g m over %d hits; %d "
      "rays grazing a corner\n",
      rays, hits, max_difference_m, grazing_incidence, max_circle_error_m, circle_hits,
      grazing_corners);
  EXPECT_GT(hits, rays / 2);
  EXPECT_LE(grazing_corners, rays / 10000);
}

// Every ray against every shape, without the caster's angular intervals or its depth test, with
// the caster's own shape geometry (its transforms in its order of operations) and intersection
// formulas: what the caster must return to the bit if its culling only ever drops tests that
// could not have shortened a range.
std::vector<double> BruteForceRanges(const b2World& world, const b2Body* ignore,
                                     const std::vector<Ray>& rays) {
  struct Xf {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    double c = 1.0, s = 0.0;
    Eigen::Vector2d Apply(const Eigen::Vector2d& v) const {
      return {p.x() + c * v.x() - s * v.y(), p.y() + s * v.x() + c * v.y()};
    }
    Eigen::Vector2d Rotate(const Eigen::Vector2d& v) const {
      return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
    }
  };
  struct Seg {
    Eigen::Vector2d a, e, normal;
    bool one_sided;
  };
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  auto vec = [](const b2Vec2& v) {
    return Eigen::Vector2d(static_cast<double>(v.x), static_cast<double>(v.y));
  };
  std::vector<Seg> segments;
  std::vector<std::pair<Eigen::Vector2d, double>> circles;
  for (const b2Body* body = world.GetBodyList(); body != nullptr; body = body->GetNext()) {
    if (body == ignore) continue;
    const b2Transform& t = body->GetTransform();
    const Xf body_xf{vec(t.p), static_cast<double>(t.q.c), static_cast<double>(t.q.s)};
    const bool is_static = body->GetType() == b2_staticBody;
    // Static shapes are cached in the world frame, moving ones in the body frame.
    const Xf cached = is_static ? body_xf : Xf{};
    auto place = [&](const Seg& s) {
      return is_static ? s
                       : Seg{body_xf.Apply(s.a), body_xf.Rotate(s.e), body_xf.Rotate(s.normal),
                             s.one_sided};
    };
    for (const b2Fixture* f = body->GetFixtureList(); f != nullptr; f = f->GetNext()) {
      if (f->IsSensor()) continue;
      if (const auto* polygon = dynamic_cast<const b2PolygonShape*>(f->GetShape())) {
        for (int i = 0; i < polygon->m_count; ++i) {
          const Eigen::Vector2d a = cached.Apply(vec(polygon->m_vertices[i]));
          const Eigen::Vector2d b =
              cached.Apply(vec(polygon->m_vertices[(i + 1) % polygon->m_count]));
          segments.push_back(place({a, b - a, cached.Rotate(vec(polygon->m_normals[i])), true}));
        }
      } else if (const auto* edge = dynamic_cast<const b2EdgeShape*>(f->GetShape())) {
        const Eigen::Vector2d a = cached.Apply(vec(edge->m_vertex1));
        const Eigen::Vector2d e = cached.Apply(vec(edge->m_vertex2)) - a;
        segments.push_back(
            place({a, e, Eigen::Vector2d(e.y(), -e.x()).normalized(), edge->m_oneSided}));
      } else if (const auto* circle = dynamic_cast<const b2CircleShape*>(f->GetShape())) {
        const Eigen::Vector2d c = cached.Apply(vec(circle->m_p));
        circles.push_back({is_static ? c : body_xf.Apply(c), circle->m_radius});
      }
    }
  }
  std::vector<double> ranges(rays.size(), kInf);
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const Ray& ray = rays[k];
    for (const Seg& s : segments) {
      const double denom = cross(ray.direction, s.e);
      if (denom == 0.0 || (s.one_sided && ray.direction.dot(s.normal) >= 0.0)) continue;
      const Eigen::Vector2d w = s.a - ray.origin;
      const double t = cross(w, s.e) / denom, u = cross(w, ray.direction) / denom;
      if (t >= 0.0 && u >= 0.0 && u <= 1.0) ranges[k] = std::min(ranges[k], t);
    }
    for (const auto& [center, radius] : circles) {
      const Eigen::Vector2d w = ray.origin - center;
      const double b = w.dot(ray.direction);
      const double disc = b * b - (w.squaredNorm() - radius * radius);
      if (disc < 0.0) continue;
      const double t = -b - std::sqrt(disc);
      if (t >= 0.0) ranges[k] = std::min(ranges[k], t);
    }
    if (ranges[k] > kMaxRange) ranges[k] = kInf;
  }
  return ranges;
}

TEST(RayCasterTest, CullingNeverChangesABitAgainstBruteForce) {
  int compared = 0, hits = 0;
  for (std::uint64_t seed = 11; seed <= 14; ++seed) {
    RandomWorld w(seed);
    RayCaster caster(&w.world, w.robot);
    RandomStream rng(seed, "origins");
    b2Body* mover = nullptr;
    for (b2Body* body = w.world.GetBodyList(); body != nullptr; body = body->GetNext()) {
      if (body->GetType() == b2_kinematicBody) mover = body;
    }
    ASSERT_NE(mover, nullptr);
    for (int trial = 0; trial < 6; ++trial) {
      // The moving body goes elsewhere between fans: its shapes are placed at cast time.
      const auto angle = static_cast<float>(3.0 * rng.Uniform());  // drawn before the position
      const Eigen::Vector2d position = RandomPoint(rng, 4.0, -4.0);
      mover->SetTransform(
          b2Vec2(static_cast<float>(position.x()), static_cast<float>(position.y())), angle);
      const Eigen::Vector2d origin = RandomPoint(rng, 20.0, 20.0);
      const bool moving = trial % 2 == 1;
      const Eigen::Vector2d motion =
          moving ? Eigen::Vector2d(0.4 * rng.Uniform(), 0.1) : Eigen::Vector2d::Zero();
      const auto fan = Fan(origin, 2.0 * std::numbers::pi * rng.Uniform(), 1.5 * std::numbers::pi,
                           1081, motion, moving ? 0.05 : 0.0);
      std::vector<double> ranges(fan.size());
      caster.Cast(fan, kMaxRange, ranges);
      const std::vector<double> expected = BruteForceRanges(w.world, w.robot, fan);
      for (std::size_t i = 0; i < fan.size(); ++i) {
        ++compared;
        hits += expected[i] != kInf;
        ASSERT_EQ(std::bit_cast<std::uint64_t>(ranges[i]),
                  std::bit_cast<std::uint64_t>(expected[i]))
            << "seed " << seed << " trial " << trial << " ray " << i << ": caster " << ranges[i]
            << " vs brute force " << expected[i];
      }
    }
  }
  EXPECT_GT(hits, compared / 2);
}

TEST(RayCasterTest, IgnoresTheRobotAndRaysFromInsideSolids) {
  b2World world(b2Vec2(0.0f, 0.0f));
  b2BodyDef def;
  b2Body* ground = world.CreateBody(&def);
  b2CircleShape pillar;
  pillar.m_p.Set(0.0f, 0.0f);
  pillar.m_radius = 1.0f;
  ground->CreateFixture(&pillar, 0.0f);
  b2PolygonShape far_box;
  far_box.SetAsBox(0.5f, 0.5f, b2Vec2(5.0f, 0.0f), 0.0f);
  ground->CreateFixture(&far_box, 0.0f);
  RayCaster caster(&world);
  // From inside the pillar the ray passes out through it (as in Box2D) and hits the box.
  const std::vector<Ray> rays = {{{0.0, 0.0}, {1.0, 0.0}, 0.0}};
  std::vector<double> ranges(1);
  caster.Cast(rays, 30.0, ranges);
  EXPECT_NEAR(ranges[0], 4.5, 1e-6);
}

// A glass pane (box) at x = 4 in front of a matte wall at x = 8, a black pane at y = 4 in front of
// a matte wall at y = 8, and a glass disc: returns only within kSpecularReturnDeg of the normal.
TEST(RayCasterTest, GlassAndBlackReturnOnlyNearNormalIncidence) {
  b2World world(b2Vec2(0.0f, 0.0f));
  b2BodyDef def;
  b2Body* ground = world.CreateBody(&def);
  std::unordered_map<const b2Fixture*, SurfaceMaterial> materials;
  auto add_box = [&](float hx, float hy, b2Vec2 c, SurfaceMaterial m) {
    b2PolygonShape box;
    box.SetAsBox(hx, hy, c, 0.0f);
    const b2Fixture* f = ground->CreateFixture(&box, 0.0f);
    if (m != SurfaceMaterial::kMatte) materials[f] = m;
  };
  add_box(0.05f, 50.0f, b2Vec2(4.0f, 0.0f), SurfaceMaterial::kGlass);
  add_box(0.05f, 50.0f, b2Vec2(8.0f, 0.0f), SurfaceMaterial::kMatte);
  add_box(3.0f, 0.05f, b2Vec2(0.0f, 4.0f), SurfaceMaterial::kBlack);
  add_box(3.0f, 0.05f, b2Vec2(0.0f, 8.0f), SurfaceMaterial::kMatte);
  b2CircleShape disc;
  disc.m_p = b2Vec2(0.0f, -5.0f);
  disc.m_radius = 1.0f;
  materials[ground->CreateFixture(&disc, 0.0f)] = SurfaceMaterial::kGlass;
  RayCaster caster(&world, nullptr, &materials);
  auto ray = [](double deg) {
    const double a = deg * std::numbers::pi / 180.0;
    return Ray{{0.0, 0.0}, {std::cos(a), std::sin(a)}, a};
  };
  // Angles in increasing order, as a scanner sweeps.
  const std::vector<Ray> rays = {ray(-95.0), ray(-90.0), ray(-5.0), ray(0.0),
                                 ray(30.0),  ray(85.0),  ray(90.0), ray(120.0)};
  std::vector<double> ranges(rays.size());
  caster.Cast(rays, 30.0, ranges);
  EXPECT_EQ(ranges[0], kInf);  // 5 deg off the disc's centre line: far off its normal, through
  EXPECT_NEAR(ranges[1], 4.0, 1e-6);                                               // disc, head on
  EXPECT_NEAR(ranges[2], 3.95 / std::cos(5.0 * std::numbers::pi / 180.0), 1e-6);   // glass, 5 deg
  EXPECT_NEAR(ranges[3], 3.95, 1e-6);                                              // glass, head on
  EXPECT_NEAR(ranges[4], 7.95 / std::cos(30.0 * std::numbers::pi / 180.0), 1e-6);  // through
  EXPECT_NEAR(ranges[5], 3.95 / std::cos(5.0 * std::numbers::pi / 180.0), 1e-6);   // black, 5 deg
  EXPECT_NEAR(ranges[6], 3.95, 1e-6);                                              // black, head on
  EXPECT_EQ(ranges[7], kInf);  // black at 30 deg off the normal: swallowed, the wall behind hidden

  // Without materials every surface is matte, bit for bit the caster it always was.
  RayCaster matte(&world);
  std::vector<double> plain(rays.size());
  matte.Cast(rays, 30.0, plain);
  EXPECT_NEAR(plain[4], 3.95 / std::cos(30.0 * std::numbers::pi / 180.0), 1e-6);
  EXPECT_NEAR(plain[7], 3.95 / std::cos(30.0 * std::numbers::pi / 180.0), 1e-6);
}

}  // namespace
}  // namespace slamrig::sim
