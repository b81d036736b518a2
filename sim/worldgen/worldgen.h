#pragma once

#include <string>

#include "sim/world_spec.h"
#include "sim/worldgen/layout.h"
#include "sim/worldgen/route.h"
#include "sim/worldgen/world_kinds.h"
#include "slam/config/yaml_node.h"
#include "slam/io/map_server.h"

namespace slamrig::sim::worldgen {

/// A generated world: an ordinary WorldSpec (walls and a waypoint drive over its route), with
/// the layout and route it was made from.
struct GeneratedWorld {
  GenerateSpec spec;
  Layout layout;
  Route route;
  WorldSpec world;
};

/// Reads a `generate:` map strictly: `kind` (required), `seed`, and the fields of that kind's
/// options and of RouteOptions, all flat (`{kind: office, seed: 7, width_m: 80, laps: 2}`).
/// A bad kind or value is a ConfigError at its key; unknown keys are left to the caller's
/// CheckAllKeysUsed().
GenerateSpec ParseGenerateSpec(const YamlNode& node);

/// The spec as the flat `generate:` map ParseGenerateSpec reads back (every field of its kind).
std::string GenerateSpecToYaml(const GenerateSpec& spec);

/// Makes the world. Same spec, same world, bit for bit. Throws ParameterError naming the
/// parameter when the world cannot hold its route.
GeneratedWorld Generate(const GenerateSpec& spec);

/// ParseGenerateSpec and Generate, with a world that cannot be made reported at the parameter's
/// key in `node` (or at `node` when the parameter is not written there).
WorldSpec GenerateWorld(const YamlNode& node);

/// The walls on a map_server grid over the world's extent: a cell is occupied when a wall comes
/// within half a cell of its centre, else free.
slam::MapImage RasteriseWalls(const GeneratedWorld& world);

/// The map as map_server files: a binary PGM (trinary: 0 occupied, 254 free) and its YAML.
std::string MapPgm(const slam::MapImage& map);
std::string MapYaml(const slam::MapImage& map, const std::string& image_file);

/// A picture of the world (walls by material, the route, the start) as PNG bytes.
std::string RenderPng(const GeneratedWorld& world);

/// Writes DIR/world.yaml (loadable by `slamrig simulate` and scenarios), DIR/map.pgm,
/// DIR/map.yaml and DIR/world.png, each atomically.
void WriteGeneratedWorld(const GeneratedWorld& world, const std::string& dir);

}  // namespace slamrig::sim::worldgen
