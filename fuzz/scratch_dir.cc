#include "fuzz/scratch_dir.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace slamrig::fuzz {
namespace {

namespace fs = std::filesystem;

// Links `link` to `target` when the target exists (a trimmed checkout may lack a folder).
void LinkIfPresent(const fs::path& target, const fs::path& link) {
  std::error_code ec;
  if (fs::exists(target, ec)) fs::create_directory_symlink(target, link);
}

}  // namespace

ScratchDir& ScratchDir::Get() {
  static ScratchDir dir;
  return dir;
}

ScratchDir::ScratchDir() {
  std::string pattern = (fs::temp_directory_path() / "slamrig_fuzz_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error("cannot create a scratch folder from " + pattern);
  }
  path_ = pattern;
  const fs::path source = SLAMRIG_SOURCE_DIR;
  LinkIfPresent(source / "worlds", path_ / "worlds");
  LinkIfPresent(source / "robots", path_ / "robots");
  LinkIfPresent(source / "worlds" / "maps", path_ / "maps");
  // Scenario files are linked one by one so that fuzzed inputs can be written beside them and
  // a sweep's `scenario: ../office_loop.yaml` finds its base from scenarios/sweeps/.
  fs::create_directories(path_ / "scenarios" / "sweeps");
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(source / "scenarios", ec)) {
    if (entry.path().extension() == ".yaml") {
      fs::create_symlink(entry.path(), path_ / "scenarios" / entry.path().filename());
    }
  }
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

std::string ScratchDir::Write(const std::string& relative_path, std::string_view bytes) const {
  const fs::path file = path_ / relative_path;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write scratch file " + file.string());
  return file.string();
}

void ScratchDir::Remove(const std::string& relative_path) const {
  std::error_code ec;
  fs::remove(path_ / relative_path, ec);
}

}  // namespace slamrig::fuzz
