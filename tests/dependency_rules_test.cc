// The dependency rules of docs/architecture.md, checked on the code's own includes: one folder is
// one module, modules only include modules listed before them in the top-level CMakeLists.txt's
// SLAMRIG_MODULES (arrows only point down), nothing under slam/ includes the simulator, Box2D or
// MuJoCo, and sim/ includes nothing of scenarios/ or apps/.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/util/read_file.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;

const fs::path kRoot = SLAMRIG_SOURCE_DIR;

// SLAMRIG_MODULES, bottom-up, as the top-level CMakeLists.txt lists them.
std::vector<std::string> Modules() {
  const std::string cmake = ReadFile(kRoot / "CMakeLists.txt");
  const std::size_t begin = cmake.find("set(SLAMRIG_MODULES");
  const std::size_t end = cmake.find(')', begin);
  std::istringstream list(cmake.substr(begin + 19, end - begin - 19));
  std::vector<std::string> modules;
  for (std::string m; list >> m;) modules.push_back(m);
  return modules;
}

// The module a repository path belongs to: the longest module folder that contains it.
int ModuleOf(const std::vector<std::string>& modules, const std::string& path) {
  int best = -1;
  std::size_t best_length = 0;
  for (std::size_t i = 0; i < modules.size(); ++i) {
    const std::string& m = modules[i];
    if (path.compare(0, m.size() + 1, m + "/") == 0 && m.size() > best_length) {
      best = static_cast<int>(i);
      best_length = m.size();
    }
  }
  return best;
}

struct Include {
  std::string file;    // repository path of the including file
  std::string target;  // what it includes, as written
};

std::vector<Include> Includes() {
  std::vector<Include> includes;
  const std::regex line(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
  for (const char* top : {"slam", "sim", "scenarios", "apps"}) {
    for (const auto& entry : fs::recursive_directory_iterator(kRoot / top)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cc") continue;
      const std::string file = fs::relative(entry.path(), kRoot).string();
      std::istringstream text(ReadFile(entry.path()));
      for (std::string l; std::getline(text, l);) {
        std::smatch m;
        if (std::regex_search(l, m, line)) includes.push_back({file, m[1]});
      }
    }
  }
  return includes;
}

TEST(DependencyRulesTest, ModulesOnlyIncludeModulesBelowThem) {
  const std::vector<std::string> modules = Modules();
  ASSERT_GT(modules.size(), 10u);
  std::vector<std::string> violations;
  int checked = 0;
  for (const Include& inc : Includes()) {
    if (inc.target.rfind("tests/", 0) == 0) continue;  // shared test helpers
    const int from = ModuleOf(modules, inc.file);
    const int to = ModuleOf(modules, inc.target);
    if (from < 0 || to < 0) continue;  // system and library headers
    ++checked;
    if (to > from) violations.push_back(inc.file + " includes " + inc.target);
  }
  EXPECT_GT(checked, 200);
  EXPECT_THAT(violations, ::testing::IsEmpty());
}

TEST(DependencyRulesTest, SlamNeverSeesTheSimulatorAndSimNeverTheRunner) {
  std::vector<std::string> violations;
  for (const Include& inc : Includes()) {
    const bool in_slam = inc.file.rfind("slam/", 0) == 0;
    const bool in_sim = inc.file.rfind("sim/", 0) == 0;
    const std::string& t = inc.target;
    if (in_slam &&
        (t.rfind("sim/", 0) == 0 || t.rfind("box2d", 0) == 0 || t.rfind("mujoco", 0) == 0 ||
         t.rfind("scenarios/", 0) == 0 || t.rfind("apps/", 0) == 0)) {
      violations.push_back(inc.file + " includes " + t);
    }
    if (in_sim && (t.rfind("scenarios/", 0) == 0 || t.rfind("apps/", 0) == 0)) {
      violations.push_back(inc.file + " includes " + t);
    }
  }
  EXPECT_THAT(violations, ::testing::IsEmpty());
}

// slam/io/bag is its own library (slamrig_bag), which slamrig_io links for its log reader: the
// bag code may use slam/io's header-only types and slamrig_atomic_file, never code compiled into
// slamrig_io, or the two libraries would need each other.
TEST(DependencyRulesTest, BagNeedsNoCodeOfSlamrigIo) {
  const std::vector<std::string> allowed = {"slam/io/atomic_file.h", "slam/io/dataset.h",
                                            "slam/io/record_sink.h"};
  std::vector<std::string> violations;
  int checked = 0;
  for (const Include& inc : Includes()) {
    if (inc.file.rfind("slam/io/bag/", 0) != 0 || inc.file.find("_test.cc") != std::string::npos ||
        inc.file.rfind("slam/io/bag/testing/", 0) == 0) {
      continue;  // the tests and test tools link slamrig_io itself
    }
    if (inc.target.rfind("slam/io/", 0) != 0 || inc.target.rfind("slam/io/bag/", 0) == 0) continue;
    ++checked;
    if (std::find(allowed.begin(), allowed.end(), inc.target) == allowed.end()) {
      violations.push_back(inc.file + " includes " + inc.target);
    }
  }
  EXPECT_GT(checked, 0);
  EXPECT_THAT(violations, ::testing::IsEmpty());
}

}  // namespace
}  // namespace slamrig
