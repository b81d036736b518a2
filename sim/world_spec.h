#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "sim/driver.h"
#include "sim/shape_spec.h"
#include "slam/types/pose2.h"

namespace slamrig::sim {

/// Friction properties of a floor surface under a wheel.
struct SurfaceSpec {
  double mu = 0.8;                    ///< Coulomb friction coefficient, tyre on this floor
  double rolling_resistance = 0.015;  ///< rolling resistance coefficient (force / normal load)

  /// One message per broken rule, e.g. "mu = -0.1; must be >= 0".
  std::vector<std::string> Validate() const;
};

/// A floor region with its own surface (ice, carpet). Sensors never see zones.
struct ZoneSpec {
  std::string name;     ///< for people reading the file ("ice", "carpet")
  ShapeSpec shape;      ///< box, polygon or circle in the map frame
  SurfaceSpec surface;  ///< the floor inside

  /// One message per broken rule, relative to the zone ("mu = ...", "shape.radius_m = ...");
  /// the surface fields sit directly in the zone.
  std::vector<std::string> Validate() const;
};

/// A moving obstacle (a trolley, a person): a kinematic body carried along a path at constant
/// speed, seen by the lidar and pushing the robot when they meet.
struct ObstacleSpec {
  std::string name;                     ///< for people reading the file
  ShapeSpec shape;                      ///< box or circle in the obstacle's own frame
  std::vector<Eigen::Vector2d> path_m;  ///< map-frame path of the obstacle frame's origin
  double speed_m_s = 0.8;               ///< constant speed along the path
  bool loop = true;  ///< true: back to the first point and again; false: to and fro

  /// One message per broken rule, field names relative to the obstacle.
  std::vector<std::string> Validate() const;
};

/// Static walls imported from a ROS map_server map (PGM + YAML). Occupied cells are merged into
/// a small number of axis-aligned (in the map's frame) boxes.
struct MapImportSpec {
  std::string yaml_path;         ///< map_server YAML; relative paths are relative to the world file
  int occupied_min = 65;         ///< a cell with occupancy >= this (0..100) is a wall
  bool unknown_is_wall = false;  ///< treat unknown (-1) cells as walls

  /// One message per broken rule.
  std::vector<std::string> Validate() const;
};

/// Everything a simulated world is made of. Plain data: World builds it; world_yaml reads it.
struct WorldSpec {
  std::string name;                     ///< written into logs and reports
  Pose2 spawn;                          ///< initial map_from_base of the robot
  SurfaceSpec floor;                    ///< surface everywhere outside zones
  std::vector<ShapeSpec> walls;         ///< static geometry
  std::optional<MapImportSpec> map;     ///< more static geometry from a map_server map
  std::vector<ZoneSpec> zones;          ///< later zones win where zones overlap
  std::vector<ObstacleSpec> obstacles;  ///< moving obstacles
  DriveOptions drive;                   ///< the default way to drive through this world

  /// One message per broken rule, field names as in the world file ("zones[1].mu = -1; ...").
  std::vector<std::string> Validate() const;
};

}  // namespace slamrig::sim
