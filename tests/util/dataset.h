#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace slamrig::testing {

/// The datasets folder: $SLAMRIG_DATA_DIR, else ../shared/datasets beside the source tree.
inline std::filesystem::path DataDir() {
  const char* env = std::getenv("SLAMRIG_DATA_DIR");
  if (env != nullptr && *env != '\0') return env;
#ifdef SLAMRIG_SOURCE_DIR
  return std::filesystem::path(SLAMRIG_SOURCE_DIR) / ".." / "shared" / "datasets";
#else
  return std::filesystem::path("..") / "shared" / "datasets";
#endif
}

/// True when running under CI (CI=true), where every dataset must be present.
inline bool InCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace slamrig::testing

/// Declares `var` as the path of dataset file `relative` (e.g.
/// "carmen_corrected/intel-corrected.log.gz"). When it is missing the test is skipped with a
/// message naming the file, or fails under CI=true, where the datasets are always there.
#define SLAMRIG_REQUIRE_DATASET(var, relative)                                     \
  const std::string var = (::slamrig::testing::DataDir() / (relative)).string();   \
  if (!std::filesystem::exists(var)) {                                             \
    if (::slamrig::testing::InCi()) FAIL() << "dataset missing under CI: " << var; \
    GTEST_SKIP() << "dataset missing: " << var << " (set SLAMRIG_DATA_DIR)";       \
  }
