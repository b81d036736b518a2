#pragma once

#include <optional>
#include <string>
#include <vector>

namespace slamrig::sim {

/// The robot preset of a simulation that names none: `slamrig simulate` without --robot and a
/// scenario without `robot:`.
inline constexpr const char* kDefaultRobot = "ece276a";

/// Where shipped presets of `folder` ("worlds", "robots", "scenarios") are looked for, in order:
/// under the current directory, in share/slamrig beside the running binary (an installed
/// slamrig), in the configured install prefix, and in the source tree this binary was built from.
std::vector<std::string> PresetFolders(const std::string& folder);

/// The world, robot or scenario file a user named: `name_or_path` itself when it is a file; else,
/// for a bare name ("office"), `<name>.yaml` in PresetFolders(folder). Throws ConfigError naming
/// the places it looked when none exists.
std::string FindPresetFile(const std::string& name_or_path, const std::string& folder);

}  // namespace slamrig::sim
