#pragma once

#include <string>

namespace slamrig::sim {

/// The world or robot file a user named. `name_or_path` itself when it is a file; else
/// `<folder>/<name_or_path>.yaml` (folder "worlds" or "robots") under the current directory, then
/// in the slamrig source tree this binary was built from. Throws ConfigError naming the places
/// it looked when none exists.
std::string FindPresetFile(const std::string& name_or_path, const std::string& folder);

}  // namespace slamrig::sim
