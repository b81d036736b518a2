#include "sim/world_spec.h"

#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> SurfaceSpec::Validate() const {
  std::vector<std::string> errors;
  if (!(mu >= 0.0)) errors.push_back("mu = " + FormatNumber(mu) + "; must be >= 0");
  if (!(rolling_resistance >= 0.0 && rolling_resistance < 1.0)) {
    errors.push_back("rolling_resistance = " + FormatNumber(rolling_resistance) +
                     "; must be in [0, 1)");
  }
  return errors;
}

std::vector<std::string> ZoneSpec::Validate() const {
  std::vector<std::string> errors = surface.Validate();
  if (shape.type == ShapeType::kPolyline) {
    errors.push_back("shape.type = polyline; a zone needs an area (box, polygon or circle)");
  }
  if (shape.material != SurfaceMaterial::kMatte) {
    errors.push_back(std::string("shape.material = ") + SurfaceMaterialName(shape.material) +
                     "; a zone is a floor no sensor sees, it has no material");
  }
  AppendErrors(&errors, PrefixErrors("shape", shape.Validate()));
  return errors;
}

std::vector<std::string> ObstacleSpec::Validate() const {
  std::vector<std::string> errors;
  if (shape.type != ShapeType::kBox && shape.type != ShapeType::kCircle) {
    errors.push_back(std::string("shape.type = ") + ShapeTypeName(shape.type) +
                     "; a moving obstacle is a box or a circle");
  }
  AppendErrors(&errors, PrefixErrors("shape", shape.Validate()));
  if (path_m.empty()) errors.push_back("path_m is empty; give at least one point");
  if (path_m.size() > 1 && !(speed_m_s > 0.0)) {
    errors.push_back("speed_m_s = " + FormatNumber(speed_m_s) + "; must be > 0");
  }
  for (std::size_t i = 0; i + 1 < path_m.size(); ++i) {
    if ((path_m[i + 1] - path_m[i]).norm() < 1e-3) {
      errors.push_back("path_m[" + std::to_string(i + 1) + "] repeats the point before it");
    }
  }
  return errors;
}

std::vector<std::string> MapImportSpec::Validate() const {
  std::vector<std::string> errors;
  if (yaml_path.empty()) errors.push_back("yaml_path is empty");
  if (occupied_min < 1 || occupied_min > 100) {
    errors.push_back("occupied_min = " + std::to_string(occupied_min) + "; must be in [1, 100]");
  }
  return errors;
}

std::vector<std::string> WorldSpec::Validate() const {
  std::vector<std::string> errors;
  AppendErrors(&errors, PrefixErrors("floor", floor.Validate()));
  for (std::size_t i = 0; i < walls.size(); ++i) {
    const std::string prefix = "walls[" + std::to_string(i) + "]";
    AppendErrors(&errors, PrefixErrors(prefix, walls[i].Validate()));
    if (walls[i].Contains(spawn.translation())) {
      errors.push_back(prefix + ": contains the spawn point (" + FormatNumber(spawn.x()) + ", " +
                       FormatNumber(spawn.y()) + ")");
    }
  }
  if (map) AppendErrors(&errors, PrefixErrors("map", map->Validate()));
  for (std::size_t i = 0; i < zones.size(); ++i) {
    AppendErrors(&errors, PrefixErrors("zones[" + std::to_string(i) + "]", zones[i].Validate()));
  }
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    AppendErrors(&errors,
                 PrefixErrors("obstacles[" + std::to_string(i) + "]", obstacles[i].Validate()));
  }
  AppendErrors(&errors, PrefixErrors("drive", drive.Validate()));
  return errors;
}

}  // namespace slamrig::sim
