#include "sim/world_yaml.h"

#include <filesystem>
#include <system_error>
#include <type_traits>

#include "sim/mount_pose.h"
#include "slam/config/fields.h"
#include "slam/io/map_server.h"
#include "slam/types/error.h"

namespace slamrig::sim {

// The world file's schema: one field list per struct, shared by reader and writer.

template <typename V>
void VisitFields(V& v, ShapeSpec& s) {
  v.RequiredEnum("type", s.type,
                 {{ShapeType::kBox, "box"},
                  {ShapeType::kPolygon, "polygon"},
                  {ShapeType::kPolyline, "polyline"},
                  {ShapeType::kCircle, "circle"}});
  switch (s.type) {
    case ShapeType::kBox:
      v("center_m", s.center_m);
      v("size_m", s.size_m);
      v("angle_rad", s.angle_rad);
      break;
    case ShapeType::kCircle:
      v("center_m", s.center_m);
      v("radius_m", s.radius_m);
      break;
    case ShapeType::kPolygon:
      v("points_m", s.points_m);
      break;
    case ShapeType::kPolyline:
      v("points_m", s.points_m);
      v("closed", s.closed);
      break;
  }
  // Written only when not matte, so that a world without materials resolves to the same text.
  if (!std::is_same_v<V, FieldWriter> || s.material != SurfaceMaterial::kMatte) {
    v.Enum("material", s.material,
           {{SurfaceMaterial::kMatte, "matte"},
            {SurfaceMaterial::kGlass, "glass"},
            {SurfaceMaterial::kBlack, "black"}});
  }
}

template <typename V>
void VisitFields(V& v, SurfaceSpec& s) {
  v("mu", s.mu);
  v("rolling_resistance", s.rolling_resistance);
}

template <typename V>
void VisitFields(V& v, ZoneSpec& z) {
  v("name", z.name);
  v.Struct("shape", z.shape);
  VisitFields(v, z.surface);
}

template <typename V>
void VisitFields(V& v, ObstacleSpec& o) {
  v("name", o.name);
  v.Struct("shape", o.shape);
  v("path_m", o.path_m);
  v("speed_m_s", o.speed_m_s);
  v("loop", o.loop);
}

template <typename V>
void VisitFields(V& v, MapImportSpec& m) {
  v("yaml_path", m.yaml_path);
  v("occupied_min", m.occupied_min);
  v("unknown_is_wall", m.unknown_is_wall);
}

template <typename V>
void VisitFields(V& v, ScheduleSegment& s) {
  v("duration_s", s.duration_s);
  v("v_m_s", s.v_m_s);
  v("omega_rad_s", s.omega_rad_s);
}

template <typename V>
void VisitFields(V& v, DriveOptions& d) {
  v.RequiredEnum("mode", d.mode,
                 {{DriveMode::kIdle, "idle"},
                  {DriveMode::kWaypoints, "waypoints"},
                  {DriveMode::kSchedule, "schedule"}});
  v("waypoints_m", d.waypoints_m);
  v("closed", d.closed);
  v("laps", d.laps);
  v("speed_m_s", d.speed_m_s);
  v("lookahead_m", d.lookahead_m);
  v("max_yaw_rate_rad_s", d.max_yaw_rate_rad_s);
  v("max_decel_m_s2", d.max_decel_m_s2);
  v("goal_tolerance_m", d.goal_tolerance_m);
  v("turn_in_place_rad", d.turn_in_place_rad);
  // Written only when set, so that a world without dead ends resolves to the same text.
  if (!std::is_same_v<V, FieldWriter> || d.dead_end_reach_m != 0.0) {
    v("dead_end_reach_m", d.dead_end_reach_m);
  }
  v.List("schedule", d.schedule);
}

template <typename V>
void VisitFields(V& v, WorldSpec& w) {
  v("name", w.name);
  MountPose spawn{w.spawn.x(), w.spawn.y(), w.spawn.theta()};
  v.Struct("spawn", spawn);
  w.spawn = spawn.ToPose2();
  v.Struct("floor", w.floor);
  v.List("walls", w.walls);
  v.OptionalStruct("map", w.map);
  v.List("zones", w.zones);
  v.List("obstacles", w.obstacles);
  v.Struct("drive", w.drive);
}

WorldSpec ParseWorldSpec(const YamlNode& node) {
  WorldSpec spec;
  FieldReader reader(node);
  VisitFields(reader, spec);
  if (spec.map) {
    const YamlNode map_node = node.Required("map");
    namespace fs = std::filesystem;
    spec.map->yaml_path = map_node.Required("yaml_path").ResolvePath(spec.map->yaml_path);
    const fs::path map_path(spec.map->yaml_path);
    std::error_code error;  // e.g. a name too long for the OS: no such file either
    if (!fs::exists(map_path, error)) {
      map_node.Required("yaml_path").Fail("no such map file '" + spec.map->yaml_path + "'");
    }
    try {
      slam::ReadMapServerMap(spec.map->yaml_path);
    } catch (const std::exception& e) {
      map_node.Required("yaml_path").Fail(std::string("cannot load the map: ") + e.what());
    }
  }
  node.ThrowIfInvalid(spec.Validate());
  return spec;
}

WorldSpec LoadWorldSpec(const std::string& path) {
  const YamlNode root = YamlNode::LoadFile(path);
  if (!root.IsMap()) root.Fail("a world file is a map (name, spawn, walls, ...)");
  WorldSpec spec = ParseWorldSpec(root);
  root.CheckAllKeysUsed();
  return spec;
}

std::string WorldSpecToYaml(const WorldSpec& spec) {
  return ToYaml(spec, "slamrig world (resolved: every field, defaults included)");
}

}  // namespace slamrig::sim
