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

// Collects "field = value; rule" messages.
class Rules {
 public:
  void AtLeast(const char* field, double value, double least) {
    if (!(value >= least)) Add(field, value, "must be >= " + FormatNumber(least));
  }
  void Positive(const char* field, double value) {
    if (!(value > 0.0)) Add(field, value, "must be > 0");
  }
  void Fraction(const char* field, double value) {
    if (!(value >= 0.0 && value <= 1.0)) Add(field, value, "must be in [0, 1]");
  }
  void Between(const char* field, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi)) {
      Add(field, value, "must be in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
    }
  }
  void Add(const char* field, double value, const std::string& rule) {
    errors_.push_back(std::string(field) + " = " + FormatNumber(value) + "; " + rule);
  }
  std::vector<std::string> Take() { return std::move(errors_); }

 private:
  std::vector<std::string> errors_;
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
  Rules r;
  r.Between("speed_m_s", speed_m_s, 0.05, 5.0);
  if (laps < 1 || laps > 100) r.Add("laps", laps, "must be in [1, 100]");
  r.Between("robot_radius_m", robot_radius_m, 0.05, 2.0);
  r.Between("clearance_margin_m", clearance_margin_m, 0.0, 2.0);
  r.Between("lookahead_m", lookahead_m, 0.1, 5.0);
  r.Between("map_resolution_m", map_resolution_m, 0.01, 1.0);
  return r.Take();
}

std::vector<std::string> OfficeOptions::Validate() const {
  Rules r;
  r.Between("width_m", width_m, 10.0, 500.0);
  r.Between("height_m", height_m, 10.0, 500.0);
  r.Between("corridor_width_m", corridor_width_m, 1.0, 10.0);
  r.Between("block_m", block_m, 4.0, 100.0);
  r.Between("room_m", room_m, 2.0, 50.0);
  r.Between("door_width_m", door_width_m, 0.6, 3.0);
  if (door_width_m + 0.4 > room_m) r.Add("door_width_m", door_width_m, "must be <= room_m - 0.4");
  r.Fraction("open_door_fraction", open_door_fraction);
  r.Fraction("closed_corridor_fraction", closed_corridor_fraction);
  r.Fraction("room_visit_fraction", room_visit_fraction);
  r.Between("furniture_per_10m2", furniture_per_10m2, 0.0, 10.0);
  r.Fraction("pillar_fraction", pillar_fraction);
  r.Fraction("glass_fraction", glass_fraction);
  r.Fraction("black_fraction", black_fraction);
  if (glass_fraction + black_fraction > 1.0) {
    r.Add("black_fraction", black_fraction, "glass_fraction + black_fraction must be <= 1");
  }
  return r.Take();
}

std::vector<std::string> WarehouseOptions::Validate() const {
  Rules r;
  r.Between("width_m", width_m, 10.0, 500.0);
  r.Between("height_m", height_m, 10.0, 500.0);
  r.Between("aisle_width_m", aisle_width_m, 1.0, 10.0);
  r.Between("shelf_depth_m", shelf_depth_m, 0.3, 3.0);
  r.Between("unit_m", unit_m, 0.5, 10.0);
  r.Between("cross_aisle_m", cross_aisle_m, 1.0, 10.0);
  if (cross_aisles < 2 || cross_aisles > 20)
    r.Add("cross_aisles", cross_aisles, "must be in [2, 20]");
  r.Fraction("black_fraction", black_fraction);
  return r.Take();
}

std::vector<std::string> CorridorOptions::Validate() const {
  Rules r;
  r.Between("length_m", length_m, 10.0, 2000.0);
  r.Between("hallway_width_m", hallway_width_m, 1.0, 10.0);
  r.Between("block_m", block_m, 1.0, 100.0);
  if (hallways < 2 || hallways > 20) r.Add("hallways", hallways, "must be in [2, 20]");
  if (rungs < 2 || rungs > 100) r.Add("rungs", rungs, "must be in [2, 100]");
  if (hallways == 2 && rungs == 2) {
    r.Add("rungs", rungs, "two hallways need >= 3 rungs for two loops");
  }
  r.Between("feature_spacing_m", feature_spacing_m, 2.0, 1000.0);
  r.Fraction("glass_fraction", glass_fraction);
  return r.Take();
}

std::vector<std::string> CampusOptions::Validate() const {
  Rules r;
  r.Between("width_m", width_m, 50.0, 2000.0);
  r.Between("height_m", height_m, 50.0, 2000.0);
  r.Between("street_width_m", street_width_m, 3.0, 50.0);
  r.Between("block_m", block_m, 10.0, 500.0);
  r.Fraction("building_fraction", building_fraction);
  r.Fraction("open_fraction", open_fraction);
  if (building_fraction + open_fraction > 1.0) {
    r.Add("open_fraction", open_fraction, "building_fraction + open_fraction must be <= 1");
  }
  r.Between("trees_per_1000m2", trees_per_1000m2, 0.0, 50.0);
  r.Between("post_spacing_m", post_spacing_m, 2.0, 1000.0);
  r.Fraction("glass_fraction", glass_fraction);
  r.Fraction("black_fraction", black_fraction);
  if (glass_fraction + black_fraction > 1.0) {
    r.Add("black_fraction", black_fraction, "glass_fraction + black_fraction must be <= 1");
  }
  return r.Take();
}

std::vector<std::string> MazeOptions::Validate() const {
  Rules r;
  r.Between("width_m", width_m, 4.0, 500.0);
  r.Between("height_m", height_m, 4.0, 500.0);
  r.Between("cell_m", cell_m, 0.5, 10.0);
  r.Between("wall_m", wall_m, 0.05, 1.0);
  if (wall_m >= 0.5 * cell_m) r.Add("wall_m", wall_m, "must be < cell_m / 2");
  if (extra_openings < 2 || extra_openings > 10000) {
    r.Add("extra_openings", extra_openings, "must be in [2, 10000]: the route closes >= 2 loops");
  }
  r.Fraction("black_fraction", black_fraction);
  return r.Take();
}

std::vector<std::string> GenerateSpec::Validate() const {
  std::vector<std::string> errors = route.Validate();
  switch (kind) {
    case WorldKind::kOffice:
      AppendErrors(&errors, office.Validate());
      break;
    case WorldKind::kWarehouse:
      AppendErrors(&errors, warehouse.Validate());
      break;
    case WorldKind::kCorridor:
      AppendErrors(&errors, corridor.Validate());
      break;
    case WorldKind::kCampus:
      AppendErrors(&errors, campus.Validate());
      break;
    case WorldKind::kMaze:
      AppendErrors(&errors, maze.Validate());
      break;
  }
  return errors;
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
