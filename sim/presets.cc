#include "sim/presets.h"

#include <unistd.h>

#include <filesystem>
#include <system_error>
#include <vector>

#include "slam/types/error.h"

namespace slamrig::sim {
namespace {

namespace fs = std::filesystem;

// share/slamrig beside the running binary's bin/ (an installed slamrig, wherever the prefix is).
std::optional<fs::path> InstalledShareDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return std::nullopt;
  return exe.parent_path().parent_path() / "share" / "slamrig";
}

}  // namespace

std::vector<std::string> PresetFolders(const std::string& folder) {
  std::vector<std::string> folders = {(fs::path(folder)).string()};
  if (const auto share = InstalledShareDir()) folders.push_back((*share / folder).string());
#ifdef SLAMRIG_INSTALL_DATADIR
  folders.push_back((fs::path(SLAMRIG_INSTALL_DATADIR) / folder).string());
#endif
#ifdef SLAMRIG_SOURCE_DIR
  folders.push_back((fs::path(SLAMRIG_SOURCE_DIR) / folder).string());
#endif
  return folders;
}

std::string FindPresetFile(const std::string& name_or_path, const std::string& folder) {
  std::vector<fs::path> candidates = {fs::path(name_or_path)};
  const bool bare_name = fs::path(name_or_path).filename() == fs::path(name_or_path) &&
                         fs::path(name_or_path).extension().empty();
  if (bare_name) {
    for (const std::string& f : PresetFolders(folder)) {
      candidates.push_back(fs::path(f) / (name_or_path + ".yaml"));
    }
  }
  std::string tried;
  for (const fs::path& candidate : candidates) {
    std::error_code error;  // e.g. a name too long for the OS: not there either
    if (fs::is_regular_file(candidate, error)) return candidate.lexically_normal().string();
    tried += (tried.empty() ? "" : ", ") + candidate.string();
  }
  const std::string kind = folder == "robots"      ? "robot"
                           : folder == "scenarios" ? "scenario"
                                                   : "world";
  throw ConfigError("'" + name_or_path + "': no such " + kind + " file (looked for " + tried + ")");
}

}  // namespace slamrig::sim
