#include "slam/io/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <iterator>

#include "slam/types/error.h"
#include "tests/util/read_file.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;

TEST(AtomicFileTest, ReplacesTheFileAndLeavesNoTemporary) {
  testing::TempDir dir;
  const std::string path = dir.Write("a.txt", "old contents");
  WriteFileAtomically(path, "new");
  EXPECT_EQ(ReadFile(path), "new");
  int files = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1);
}

TEST(AtomicFileTest, AFileThatCannotBeWrittenIsAnOutputErrorNamingIt) {
  testing::TempDir dir;
  dir.Write("plain", "x");
  const std::string path = dir.File("plain/a.txt");  // a folder that is a file
  try {
    WriteFileAtomically(path, "new");
    FAIL() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": cannot write"), std::string::npos) << e.what();
  }
}

TEST(AtomicFileTest, CheckOutputFolderCreatesNothing) {
  testing::TempDir dir;
  CheckOutputFolder(dir.File("new/nested"));
  EXPECT_FALSE(fs::exists(dir.File("new")));
  CheckOutputFolder(dir.path().string());
}

TEST(AtomicFileTest, CheckOutputFolderRejectsAFileInTheWay) {
  testing::TempDir dir;
  dir.Write("plain", "x");
  try {
    CheckOutputFolder(dir.File("plain/out"));
    FAIL() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("plain/out: cannot create the folder"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace slamrig::slam
