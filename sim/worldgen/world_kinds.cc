#include "sim/worldgen/world_kinds.h"

#include <utility>

#include "slam/types/validation.h"

namespace slamrig::sim::worldgen {
namespace {

constexpr std::pair<WorldKind, const char*> kKinds[] = {
    {WorldKind::kOffice, "office"},     {WorldKind::kWarehouse, "warehouse"},
    {WorldKind::kCorridor, "corridor"}, {WorldKind::kCampus, "campus"},
    {WorldKind::kMaze, "maze"},
};

}  // namespace

const char* WorldKindName(WorldKind kind) {
  for (const auto& [k, name] : kKinds) {
    if (k == kind) return name;
  }
  return "?";
}

std::string WorldKindNames() {
  std::string names;
  for (const auto& [k, name] : kKinds) names += (names.empty() ? "" : ", ") + std::string(name);
  return names;
}

bool ParseWorldKind(const std::string& name, WorldKind* kind) {
  for (const auto& [k, n] : kKinds) {
    if (name == n) {
      *kind = k;
      return true;
    }
  }
  return false;
}

std::vector<std::string> RouteOptions::Validate() const {
  Rules rules;
  rules.InRange("speed_m_s", speed_m_s, 0.05, 5.0);
  rules.InRange("laps", laps, 1, 100);
  rules.InRange("robot_radius_m", robot_radius_m, 0.05, 2.0);
  rules.InRange("clearance_margin_m", clearance_margin_m, 0.0, 2.0);
  rules.InRange("lookahead_m", lookahead_m, 0.1, 5.0);
  rules.InRange("map_resolution_m", map_resolution_m, 0.01, 1.0);
  rules.InRange("route_length_m", route_length_m, 0.0, 1e6);
  return rules.errors();
}

std::vector<std::string> OfficeOptions::Validate() const {
  Rules rules;
  rules.InRange("width_m", width_m, 10.0, 500.0);
  rules.InRange("height_m", height_m, 10.0, 500.0);
  rules.InRange("corridor_width_m", corridor_width_m, 1.0, 10.0);
  rules.InRange("block_m", block_m, 4.0, 100.0);
  rules.InRange("room_m", room_m, 2.0, 50.0);
  rules.InRange("door_width_m", door_width_m, 0.6, 3.0);
  rules.Require(door_width_m + 0.4 <= room_m, "door_width_m", door_width_m,
                "must be <= room_m - 0.4");
  rules.Fraction("open_door_fraction", open_door_fraction);
  rules.Fraction("closed_corridor_fraction", closed_corridor_fraction);
  rules.Fraction("room_visit_fraction", room_visit_fraction);
  rules.InRange("furniture_per_10m2", furniture_per_10m2, 0.0, 10.0);
  rules.Fraction("pillar_fraction", pillar_fraction);
  rules.Fraction("glass_fraction", glass_fraction);
  rules.Fraction("black_fraction", black_fraction);
  rules.Require(glass_fraction + black_fraction <= 1.0, "black_fraction", black_fraction,
                "glass_fraction + black_fraction must be <= 1");
  return rules.errors();
}

std::vector<std::string> WarehouseOptions::Validate() const {
  Rules rules;
  rules.InRange("width_m", width_m, 10.0, 500.0);
  rules.InRange("height_m", height_m, 10.0, 500.0);
  rules.InRange("aisle_width_m", aisle_width_m, 1.0, 10.0);
  rules.InRange("shelf_depth_m", shelf_depth_m, 0.3, 3.0);
  rules.InRange("unit_m", unit_m, 0.5, 10.0);
  rules.InRange("cross_aisle_m", cross_aisle_m, 1.0, 10.0);
  rules.InRange("cross_aisles", cross_aisles, 2, 20);
  rules.Fraction("black_fraction", black_fraction);
  return rules.errors();
}

std::vector<std::string> CorridorOptions::Validate() const {
  Rules rules;
  rules.InRange("length_m", length_m, 10.0, 2000.0);
  rules.InRange("hallway_width_m", hallway_width_m, 1.0, 10.0);
  rules.InRange("block_m", block_m, 1.0, 100.0);
  rules.InRange("hallways", hallways, 2, 20).InRange("rungs", rungs, 2, 100);
  rules.Require(hallways != 2 || rungs != 2, "rungs", rungs,
                "two hallways need >= 3 rungs for two loops");
  rules.InRange("feature_spacing_m", feature_spacing_m, 2.0, 1000.0);
  rules.Fraction("glass_fraction", glass_fraction);
  return rules.errors();
}

std::vector<std::string> CampusOptions::Validate() const {
  Rules rules;
  rules.InRange("width_m", width_m, 50.0, 2000.0);
  rules.InRange("height_m", height_m, 50.0, 2000.0);
  rules.InRange("street_width_m", street_width_m, 3.0, 50.0);
  rules.InRange("block_m", block_m, 10.0, 500.0);
  rules.Fraction("building_fraction", building_fraction);
  rules.Fraction("open_fraction", open_fraction);
  rules.Require(building_fraction + open_fraction <= 1.0, "open_fraction", open_fraction,
                "building_fraction + open_fraction must be <= 1");
  rules.InRange("trees_per_1000m2", trees_per_1000m2, 0.0, 50.0);
  rules.InRange("post_spacing_m", post_spacing_m, 2.0, 1000.0);
  rules.Fraction("glass_fraction", glass_fraction);
  rules.Fraction("black_fraction", black_fraction);
  rules.Require(glass_fraction + black_fraction <= 1.0, "black_fraction", black_fraction,
                "glass_fraction + black_fraction must be <= 1");
  return rules.errors();
}

std::vector<std::string> MazeOptions::Validate() const {
  Rules rules;
  rules.InRange("width_m", width_m, 4.0, 500.0);
  rules.InRange("height_m", height_m, 4.0, 500.0);
  rules.InRange("cell_m", cell_m, 0.5, 10.0);
  rules.InRange("wall_m", wall_m, 0.05, 1.0);
  rules.Require(wall_m < 0.5 * cell_m, "wall_m", wall_m, "must be < cell_m / 2");
  rules.Require(extra_openings >= 2 && extra_openings <= 10000, "extra_openings", extra_openings,
                "must be in [2, 10000]: the route closes >= 2 loops");
  rules.Fraction("black_fraction", black_fraction);
  return rules.errors();
}

std::vector<std::string> GenerateSpec::Validate() const {
  // The route's and the kind's keys sit side by side at the top of `generate:`.
  Rules rules;
  rules.Nested("", route.Validate());
  switch (kind) {
    case WorldKind::kOffice:
      rules.Nested("", office.Validate());
      break;
    case WorldKind::kWarehouse:
      rules.Nested("", warehouse.Validate());
      break;
    case WorldKind::kCorridor:
      rules.Nested("", corridor.Validate());
      break;
    case WorldKind::kCampus:
      rules.Nested("", campus.Validate());
      break;
    case WorldKind::kMaze:
      rules.Nested("", maze.Validate());
      break;
  }
  return rules.errors();
}

RouteOptions DefaultRouteOptions(WorldKind kind) {
  RouteOptions route;
  if (kind == WorldKind::kCampus) {
    route.speed_m_s = 1.0;
    route.lookahead_m = 1.0;
    route.map_resolution_m = 0.1;
  }
  if (kind == WorldKind::kMaze) route.speed_m_s = 0.4;
  return route;
}

}  // namespace slamrig::sim::worldgen
