#pragma once

#include <string>

#include "sim/robot_spec.h"
#include "slam/config/yaml_node.h"

namespace slamrig::sim {

/// Reads a robot preset (robots/*.yaml) strictly: unknown keys, wrong types and broken rules are
/// a ConfigError naming file, line, column and key path. Absent keys keep RobotSpec's defaults.
RobotSpec LoadRobotSpec(const std::string& path);

/// Reads a robot from `node` (e.g. the `robot:` section of a scenario). Unknown keys are left to
/// the caller's CheckAllKeysUsed() on the document root.
RobotSpec ParseRobotSpec(const YamlNode& node);

/// The fully resolved robot as YAML that LoadRobotSpec reads back to an equal spec.
std::string RobotSpecToYaml(const RobotSpec& spec);

}  // namespace slamrig::sim
