#pragma once

#include <box2d/box2d.h>

#include <Eigen/Core>
#include <memory>
#include <unordered_map>
#include <vector>

#include "sim/world_spec.h"
#include "slam/types/time.h"

namespace slamrig::sim {

/// The Box2D world built from a WorldSpec (top-down, no gravity): one static body holding every
/// wall and every box merged from an imported map, one kinematic body per moving obstacle, and the
/// floor zones, which are not physical: SurfaceAt() looks them up by point, so no sensor sees them.
/// Walls become Box2D shapes as follows: a box or a convex polygon of at most 8 vertices is one
/// solid polygon; any other polygon and every polyline are two-sided edges; a circle is a circle.
class World {
 public:
  /// Builds the world; reads the imported map, if any (a ParseError names the map file). `spec`
  /// must be valid (checked).
  explicit World(const WorldSpec& spec);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// The surface under `point_m` (map frame): the last zone containing it, else the floor.
  const SurfaceSpec& SurfaceAt(const Eigen::Vector2d& point_m) const;

  /// Sets each obstacle's velocity so that it is where its path says at `time + dt_s`. Call before
  /// stepping the Box2D world from `time` by `dt_s`.
  void MoveObstacles(Time time, double dt_s);

  /// Where obstacle `index` should be at `time` (map frame).
  Eigen::Vector2d ObstaclePositionAt(std::size_t index, Time time) const;

  /// The Box2D world, for stepping and ray casts.
  b2World* b2world() { return world_.get(); }
  /// The Box2D world, read-only.
  const b2World* b2world() const { return world_.get(); }
  /// The spec it was built from.
  const WorldSpec& spec() const { return spec_; }
  /// Boxes the imported map was merged into (0 without a map).
  int num_map_boxes() const { return num_map_boxes_; }
  /// The fixtures whose surface is not matte, with their material (for the RayCaster).
  const std::unordered_map<const b2Fixture*, SurfaceMaterial>& materials() const {
    return materials_;
  }

 private:
  struct ObstaclePath {
    std::vector<Eigen::Vector2d> points;  // closing point repeated for a loop
    std::vector<double> cumulative_m;
    double speed_m_s = 0.0;
    bool loop = true;
  };
  void AddWall(const ShapeSpec& shape, b2Body* body);

  WorldSpec spec_;
  std::unique_ptr<b2World> world_;
  b2Body* static_body_ = nullptr;
  std::vector<b2Body*> obstacle_bodies_;
  std::vector<ObstaclePath> obstacle_paths_;
  int num_map_boxes_ = 0;
  std::unordered_map<const b2Fixture*, SurfaceMaterial> materials_;
};

}  // namespace slamrig::sim
