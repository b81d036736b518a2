#include "apps/data_path.h"

#include <cstdlib>
#include <filesystem>

namespace slamrig::app {

std::string DataDir() {
  const char* env = std::getenv("SLAMRIG_DATA_DIR");
  return env != nullptr && *env != '\0' ? env : "../shared/datasets";
}

std::string ResolveDataPath(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) return path;
  const std::filesystem::path in_data = std::filesystem::path(DataDir()) / path;
  if (std::filesystem::path(path).is_relative() && std::filesystem::exists(in_data, ec)) {
    return in_data.string();
  }
  return path;
}

}  // namespace slamrig::app
