#pragma once

#include <string>

#include "sim/world_spec.h"
#include "slam/config/yaml_node.h"

namespace slamrig::sim {

/// Reads a world file (worlds/*.yaml) strictly: unknown keys, wrong types and broken rules are a
/// ConfigError naming file, line, column and key path. A relative map path is resolved against
/// the file's folder and stored absolute, and the map is read once to check it (its errors are
/// reported too, after the world file's own location).
WorldSpec LoadWorldSpec(const std::string& path);

/// Reads a world from `node` (e.g. the `world:` section of a scenario). Unknown keys are left to
/// the caller's CheckAllKeysUsed() on the document root.
WorldSpec ParseWorldSpec(const YamlNode& node);

/// The fully resolved world as YAML that LoadWorldSpec reads back to an equal spec.
std::string WorldSpecToYaml(const WorldSpec& spec);

}  // namespace slamrig::sim
