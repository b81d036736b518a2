#include "sim/world.h"

#include <algorithm>
#include <cmath>

#include "sim/map_import.h"
#include "slam/io/map_server.h"
#include "slam/types/check.h"

namespace slamrig::sim {
namespace {

b2Vec2 ToB2(const Eigen::Vector2d& v) {
  return b2Vec2(static_cast<float>(v.x()), static_cast<float>(v.y()));
}

// Friction of the walls against the robot's bumper; the robot's own fixture sets the other half.
constexpr float kWallFriction = 0.5f;

b2FixtureDef WallFixtureDef(const b2Shape* shape) {
  b2FixtureDef def;
  def.shape = shape;
  def.friction = kWallFriction;
  def.restitution = 0.0f;
  def.density = 1.0f;
  return def;
}

}  // namespace

World::World(const WorldSpec& spec) : spec_(spec) {
  SLAMRIG_CHECK_VALID(spec_, "WorldSpec");
  world_ = std::make_unique<b2World>(b2Vec2(0.0f, 0.0f));

  b2BodyDef static_def;
  static_def.type = b2_staticBody;
  static_body_ = world_->CreateBody(&static_def);
  for (const ShapeSpec& wall : spec_.walls) AddWall(wall, static_body_);
  if (spec_.map) {
    const slam::MapImage map = slam::ReadMapServerMap(spec_.map->yaml_path);
    const std::vector<ShapeSpec> boxes = MapWallBoxes(map, *spec_.map);
    for (const ShapeSpec& box : boxes) AddWall(box, static_body_);
    num_map_boxes_ = static_cast<int>(boxes.size());
  }

  for (const ObstacleSpec& obstacle : spec_.obstacles) {
    ObstaclePath path;
    path.points = obstacle.path_m;
    path.loop = obstacle.loop;
    path.speed_m_s = obstacle.speed_m_s;
    if (path.loop && path.points.size() > 1) path.points.push_back(path.points.front());
    path.cumulative_m.assign(path.points.size(), 0.0);
    for (std::size_t i = 1; i < path.points.size(); ++i) {
      path.cumulative_m[i] =
          path.cumulative_m[i - 1] + (path.points[i] - path.points[i - 1]).norm();
    }
    obstacle_paths_.push_back(std::move(path));

    b2BodyDef def;
    def.type = b2_kinematicBody;
    def.position = ToB2(obstacle.path_m.front());
    def.allowSleep = false;
    b2Body* body = world_->CreateBody(&def);
    AddWall(obstacle.shape, body);
    obstacle_bodies_.push_back(body);
  }
}

World::~World() = default;

void World::AddWall(const ShapeSpec& shape, b2Body* body) {
  auto create = [&](const b2FixtureDef& def) {
    const b2Fixture* fixture = body->CreateFixture(&def);
    if (shape.material != SurfaceMaterial::kMatte) materials_[fixture] = shape.material;
  };
  auto add_edge = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    b2EdgeShape edge;
    edge.SetTwoSided(ToB2(a), ToB2(b));
    create(WallFixtureDef(&edge));
  };
  switch (shape.type) {
    case ShapeType::kBox: {
      b2PolygonShape box;
      box.SetAsBox(static_cast<float>(0.5 * shape.size_m.x()),
                   static_cast<float>(0.5 * shape.size_m.y()), ToB2(shape.center_m),
                   static_cast<float>(shape.angle_rad));
      create(WallFixtureDef(&box));
      break;
    }
    case ShapeType::kCircle: {
      b2CircleShape circle;
      circle.m_p = ToB2(shape.center_m);
      circle.m_radius = static_cast<float>(shape.radius_m);
      create(WallFixtureDef(&circle));
      break;
    }
    case ShapeType::kPolygon: {
      const std::vector<Eigen::Vector2d> outline = shape.Outline();
      if (shape.IsConvexPolygon()) {
        std::vector<b2Vec2> points;
        for (const auto& p : outline) points.push_back(ToB2(p));
        b2PolygonShape polygon;
        polygon.Set(points.data(), static_cast<int32>(points.size()));
        create(WallFixtureDef(&polygon));
      } else {
        for (std::size_t i = 0; i < outline.size(); ++i) {
          add_edge(outline[i], outline[(i + 1) % outline.size()]);
        }
      }
      break;
    }
    case ShapeType::kPolyline: {
      const auto& p = shape.points_m;
      for (std::size_t i = 0; i + 1 < p.size(); ++i) add_edge(p[i], p[i + 1]);
      if (shape.closed) add_edge(p.back(), p.front());
      break;
    }
  }
}

const SurfaceSpec& World::SurfaceAt(const Eigen::Vector2d& point_m) const {
  for (auto it = spec_.zones.rbegin(); it != spec_.zones.rend(); ++it) {
    if (it->shape.Contains(point_m)) return it->surface;
  }
  return spec_.floor;
}

Eigen::Vector2d World::ObstaclePositionAt(std::size_t index, Time time) const {
  const ObstaclePath& path = obstacle_paths_[index];
  if (path.points.size() < 2) return path.points.front();
  const double length = path.cumulative_m.back();
  double s = path.speed_m_s * time.seconds();
  if (path.loop) {
    s = std::fmod(s, length);
  } else {
    s = std::fmod(s, 2.0 * length);
    if (s > length) s = 2.0 * length - s;
  }
  const auto it = std::upper_bound(path.cumulative_m.begin(), path.cumulative_m.end(), s);
  const std::size_t j = std::clamp<std::size_t>(
      static_cast<std::size_t>(it - path.cumulative_m.begin()), 1, path.points.size() - 1);
  const double segment = path.cumulative_m[j] - path.cumulative_m[j - 1];
  const double f = std::clamp((s - path.cumulative_m[j - 1]) / segment, 0.0, 1.0);
  return path.points[j - 1] + f * (path.points[j] - path.points[j - 1]);
}

void World::MoveObstacles(Time time, double dt_s) {
  const Time next = AddSeconds(time, dt_s);
  for (std::size_t i = 0; i < obstacle_bodies_.size(); ++i) {
    const b2Vec2 now = obstacle_bodies_[i]->GetPosition();
    const Eigen::Vector2d target = ObstaclePositionAt(i, next);
    obstacle_bodies_[i]->SetLinearVelocity(b2Vec2(static_cast<float>((target.x() - now.x) / dt_s),
                                                  static_cast<float>((target.y() - now.y) / dt_s)));
    obstacle_bodies_[i]->SetAngularVelocity(0.0f);
  }
}

}  // namespace slamrig::sim
