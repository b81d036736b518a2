#include "sim/world_spec.h"

#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> SurfaceSpec::Validate() const {
  Rules rules;
  rules.NonNegative("mu", mu).InRange("rolling_resistance", rolling_resistance, 0.0, 1.0,
                                      Ends::kOpenHigh);
  return rules.errors();
}

std::vector<std::string> ZoneSpec::Validate() const {
  Rules rules;
  rules.Nested("", surface.Validate())
      .Require(shape.type != ShapeType::kPolyline, "shape.type", "polyline",
               "a zone needs an area (box, polygon or circle)")
      .Require(shape.material == SurfaceMaterial::kMatte, "shape.material",
               SurfaceMaterialName(shape.material),
               "a zone is a floor no sensor sees, it has no material")
      .Nested("shape", shape.Validate());
  return rules.errors();
}

std::vector<std::string> ObstacleSpec::Validate() const {
  Rules rules;
  rules.Require(shape.type == ShapeType::kBox || shape.type == ShapeType::kCircle, "shape.type",
                ShapeTypeName(shape.type), "a moving obstacle is a box or a circle");
  rules.Nested("shape", shape.Validate());
  if (path_m.empty()) rules.Add("path_m is empty; give at least one point");
  if (path_m.size() > 1) rules.Positive("speed_m_s", speed_m_s);
  for (std::size_t i = 0; i + 1 < path_m.size(); ++i) {
    if ((path_m[i + 1] - path_m[i]).norm() < 1e-3) {
      rules.Add("path_m[" + std::to_string(i + 1) + "] repeats the point before it");
    }
  }
  return rules.errors();
}

std::vector<std::string> MapImportSpec::Validate() const {
  Rules rules;
  if (yaml_path.empty()) rules.Add("yaml_path is empty");
  rules.InRange("occupied_min", occupied_min, 1, 100);
  return rules.errors();
}

std::vector<std::string> WorldSpec::Validate() const {
  Rules rules;
  rules.Nested("floor", floor.Validate());
  for (std::size_t i = 0; i < walls.size(); ++i) {
    const std::string prefix = "walls[" + std::to_string(i) + "]";
    rules.Nested(prefix, walls[i].Validate());
    if (walls[i].Contains(spawn.translation())) {
      rules.Add(prefix + ": contains the spawn point (" + FormatNumber(spawn.x()) + ", " +
                FormatNumber(spawn.y()) + ")");
    }
  }
  if (map) rules.Nested("map", map->Validate());
  for (std::size_t i = 0; i < zones.size(); ++i) {
    rules.Nested("zones[" + std::to_string(i) + "]", zones[i].Validate());
  }
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    rules.Nested("obstacles[" + std::to_string(i) + "]", obstacles[i].Validate());
  }
  rules.Nested("drive", drive.Validate());
  return rules.errors();
}

}  // namespace slamrig::sim
