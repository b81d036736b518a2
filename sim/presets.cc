#include "sim/presets.h"

#include <filesystem>
#include <system_error>
#include <vector>

#include "slam/types/error.h"

namespace slamrig::sim {

std::string FindPresetFile(const std::string& name_or_path, const std::string& folder) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates = {fs::path(name_or_path),
                                      fs::path(folder) / (name_or_path + ".yaml")};
#ifdef SLAMRIG_SOURCE_DIR
  candidates.push_back(fs::path(SLAMRIG_SOURCE_DIR) / folder / (name_or_path + ".yaml"));
#endif
  std::string tried;
  for (const fs::path& candidate : candidates) {
    std::error_code error;  // e.g. a name too long for the OS: not a candidate
    if (fs::is_regular_file(candidate, error)) return candidate.string();
    tried += (tried.empty() ? "" : ", ") + candidate.string();
  }
  throw ConfigError("'" + name_or_path + "': no such " +
                    (folder == "robots" ? std::string("robot") : std::string("world")) +
                    " file (looked for " + tried + ")");
}

}  // namespace slamrig::sim
