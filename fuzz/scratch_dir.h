#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace slamrig::fuzz {

/// A private folder for one fuzzing process, laid out like the repository so that relative
/// paths in fuzzed files resolve: `worlds/`, `robots/` and `maps/` link to the source tree's
/// folders, `scenarios/` holds links to the shipped scenario files, and inputs are written
/// beside them. Created on first use, removed when the process exits.
class ScratchDir {
 public:
  /// The one folder of this process.
  static ScratchDir& Get();

  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir();

  /// Writes `bytes` to `relative_path` inside the folder (replacing it) and returns its path.
  std::string Write(const std::string& relative_path, std::string_view bytes) const;
  /// Removes `relative_path` inside the folder if it exists.
  void Remove(const std::string& relative_path) const;

  const std::filesystem::path& path() const { return path_; }

 private:
  ScratchDir();
  std::filesystem::path path_;
};

}  // namespace slamrig::fuzz
