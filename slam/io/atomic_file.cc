#include "slam/io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "slam/types/error.h"
#include "slam/types/interrupt.h"

namespace slamrig::slam {

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  // After SIGINT/SIGTERM nothing more is put in place: the output stays visibly unfinished.
  ThrowIfInterrupted();
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) {
    throw OutputError(path + ": cannot write: " + std::strerror(errno));
  }
  const bool written = std::fwrite(contents.data(), 1, contents.size(), f) == contents.size();
  const bool flushed = std::fflush(f) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!written || !flushed || !closed) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw OutputError(path + ": write failed: " + reason);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw OutputError(path + ": cannot rename into place: " + ec.message());
  }
}

void CheckOutputFolder(const std::string& dir) {
  namespace fs = std::filesystem;
  fs::path existing = fs::absolute(dir);
  std::error_code ec;
  while (!fs::exists(existing, ec) && existing.has_parent_path() &&
         existing != existing.parent_path()) {
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, ec)) {
    throw OutputError(dir + ": cannot create the folder: " + existing.string() +
                      " is not a folder");
  }
  if (::access(existing.c_str(), W_OK) != 0) {
    throw OutputError(dir + ": cannot write: " + existing.string() + ": " + std::strerror(errno));
  }
}

}  // namespace slamrig::slam
