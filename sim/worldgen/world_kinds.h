#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace slamrig::sim::worldgen {

/// The kinds of world the generator makes.
enum class WorldKind {
  kOffice,     ///< rooms off a grid of corridors, loops of several sizes, doors, clutter, pillars
  kWarehouse,  ///< rows of identical shelving with aisles (perceptual aliasing)
  kCorridor,   ///< long, nearly featureless hallways (degenerate along their axis)
  kCampus,     ///< outdoor streets between building blocks, trees and posts, open space
  kMaze,       ///< narrow passages and dead ends
};

/// Name used on the command line and in scenarios ("office", ...).
const char* WorldKindName(WorldKind kind);
/// "office, warehouse, corridor, campus, maze".
std::string WorldKindNames();
/// The kind named `name`, or false.
bool ParseWorldKind(const std::string& name, WorldKind* kind);

/// What every kind shares: the drive and the map raster.
struct RouteOptions {
  double speed_m_s = 0.5;           ///< cruise speed of the drive
  int laps = 1;                     ///< times the robot drives the whole route
  double robot_radius_m = 0.4;      ///< the robot's footprint as a disc (ece276a: 0.37 m)
  double clearance_margin_m = 0.2;  ///< the route keeps robot_radius_m plus this from every wall
  double lookahead_m = 0.5;         ///< pure pursuit lookahead of the drive
  double map_resolution_m = 0.05;   ///< cell size of the written map
  /// The longest a lap may be: 0 drives the whole world; a shorter budget drives the part of the
  /// world nearest the start whose tour fits, loops included (a five-minute drive that still
  /// closes loops). At least one loop must fit.
  double route_length_m = 0.0;

  /// One message per broken rule, e.g. "laps = 0; must be >= 1".
  std::vector<std::string> Validate() const;
  /// The distance the route keeps from every wall.
  double clearance_m() const { return robot_radius_m + clearance_margin_m; }
};

/// `office`: a building of width_m x height_m whose corridors run on a grid (a ring along the
/// outer walls and lines between blocks of about block_m); each block is split into rooms of
/// about room_m with a door to the corridor. Some corridor stretches are closed off by doors,
/// which merges loops into larger ones.
struct OfficeOptions {
  double width_m = 60.0;                  ///< building extent along x
  double height_m = 40.0;                 ///< building extent along y
  double corridor_width_m = 2.0;          ///< free width of every corridor
  double block_m = 12.0;                  ///< target size of a block of rooms between corridors
  double room_m = 4.0;                    ///< target width of a room along its corridor
  double door_width_m = 1.4;              ///< free width of a door
  double open_door_fraction = 0.7;        ///< doors left open (the others are shut)
  double closed_corridor_fraction = 0.2;  ///< inner corridor stretches shut off by doors
  double room_visit_fraction = 0.25;      ///< open rooms the route drives into and back out of
  double furniture_per_10m2 = 1.0;        ///< desks and cabinets per 10 m^2 of room
  double pillar_fraction = 0.3;           ///< rooms with a pillar
  double glass_fraction = 0.15;           ///< corridor walls of glass
  double black_fraction = 0.05;           ///< corridor walls painted black

  std::vector<std::string> Validate() const;
};

/// `warehouse`: a hall with double-sided shelving rows of identical units, aisles between them
/// and cross aisles along the ends (and between, when cross_aisles > 2).
struct WarehouseOptions {
  double width_m = 40.0;        ///< hall extent along x (across the rows)
  double height_m = 30.0;       ///< hall extent along y (along the rows)
  double aisle_width_m = 2.6;   ///< least free width of an aisle between rows
  double shelf_depth_m = 1.1;   ///< depth of one side of a double-sided row
  double unit_m = 2.7;          ///< length of one shelving unit (every unit the same)
  double cross_aisle_m = 3.0;   ///< free width of a cross aisle
  int cross_aisles = 3;         ///< cross aisles, the two at the ends included
  double black_fraction = 0.1;  ///< units holding black-wrapped goods (returns only head on)

  std::vector<std::string> Validate() const;
};

/// `corridor`: `hallways` parallel hallways of length_m, block_m apart, joined by `rungs`
/// cross hallways (two at the ends): long, nearly featureless, with sparse features (a cabinet,
/// a half pillar, a glass stretch) about every feature_spacing_m.
struct CorridorOptions {
  double length_m = 120.0;          ///< extent along x
  double hallway_width_m = 2.0;     ///< free width of every hallway
  double block_m = 8.0;             ///< depth of the rooms between two parallel hallways
  int hallways = 2;                 ///< parallel hallways along x
  int rungs = 3;                    ///< cross hallways joining them
  double feature_spacing_m = 20.0;  ///< mean spacing of the sparse features along a wall
  double glass_fraction = 0.1;      ///< features that are glass stretches of wall

  std::vector<std::string> Validate() const;
};

/// `campus`: an open area of width_m x height_m (no outer wall) crossed by a grid of streets;
/// the blocks between hold buildings, parks with trees, or nothing (open beyond a lidar's
/// range); posts and trees line the streets.
struct CampusOptions {
  double width_m = 300.0;          ///< extent along x
  double height_m = 300.0;         ///< extent along y
  double street_width_m = 10.0;    ///< free width of a street
  double block_m = 60.0;           ///< target size of a block between streets
  double building_fraction = 0.6;  ///< blocks with a building
  double open_fraction = 0.2;      ///< blocks left empty (the rest are parks with trees)
  double trees_per_1000m2 = 2.0;   ///< tree density in parks
  double post_spacing_m = 15.0;    ///< spacing of the posts along the streets
  double glass_fraction = 0.2;     ///< buildings with glass facades
  double black_fraction = 0.1;     ///< buildings with black facades

  std::vector<std::string> Validate() const;
};

/// `maze`: a grid of cells of cell_m, carved into a spanning tree of passages by a randomised
/// depth-first search (dead ends everywhere), with extra_openings walls removed to close loops.
struct MazeOptions {
  double width_m = 24.0;        ///< extent along x
  double height_m = 16.0;       ///< extent along y
  double cell_m = 2.0;          ///< passage pitch (free width: cell_m minus the wall)
  double wall_m = 0.15;         ///< wall thickness
  int extra_openings = 4;       ///< walls removed after carving: loops in the maze
  double black_fraction = 0.1;  ///< walls painted black

  std::vector<std::string> Validate() const;
};

/// Everything `slamrig world generate` and a scenario's `world: {generate: ...}` say: the kind,
/// the seed, the kind's own options and the route's.
struct GenerateSpec {
  WorldKind kind = WorldKind::kOffice;
  std::uint64_t seed = 1;
  RouteOptions route;
  OfficeOptions office;
  WarehouseOptions warehouse;
  CorridorOptions corridor;
  CampusOptions campus;
  MazeOptions maze;

  /// The broken rules of the kind's options and the route's, field names as in the file.
  std::vector<std::string> Validate() const;
};

/// Default route options of a kind (a campus drives faster, on a coarser map).
RouteOptions DefaultRouteOptions(WorldKind kind);

}  // namespace slamrig::sim::worldgen
