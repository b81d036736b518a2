// Every input that once broke a reader (fuzz/regressions/<target>/) and every hand-made seed
// (fuzz/corpus/<target>/) goes through the same entry point as the fuzz targets: the reader
// either accepts it or rejects it with a ParseError/ConfigError, nothing else.
#include <gtest/gtest.h>

#include <filesystem>
#include <iterator>
#include <string>

#include "fuzz/reader_entries.h"
#include "tests/util/read_file.h"

namespace slamrig::fuzz {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;

// Runs every file below fuzz/<folder>/<entry>/ and returns how many there were; with
// `must_accept`, a clean rejection fails too.
int RunFolder(const std::string& folder, const ReaderEntry& entry, bool must_accept) {
  const fs::path dir = fs::path(SLAMRIG_SOURCE_DIR) / "fuzz" / folder / entry.name;
  if (!fs::is_directory(dir)) return 0;
  int files = 0;
  for (const auto& file : fs::directory_iterator(dir)) {
    if (!file.is_regular_file()) continue;
    ++files;
    SCOPED_TRACE(file.path().string());
    const std::string bytes = ReadFile(file.path());
    try {
      const ReaderResult result = RunReaderEntry(entry, bytes);
      if (must_accept) {
        EXPECT_EQ(result.outcome, ReaderOutcome::kAccepted) << result.message;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << "escaped the reader: " << e.what();
    }
  }
  return files;
}

TEST(FuzzRegressions, EveryRegressionInputIsAcceptedOrRejectedCleanly) {
  for (const ReaderEntry& entry : ReaderEntries()) RunFolder("regressions", entry, false);
}

// The hand-made seeds are valid files: a fuzzer starts from inputs that get past the parsers.
TEST(FuzzRegressions, EveryTargetHasHandMadeSeedsThatItAccepts) {
  for (const ReaderEntry& entry : ReaderEntries()) {
    EXPECT_GT(RunFolder("corpus", entry, true), 0) << "no seeds in fuzz/corpus/" << entry.name;
  }
}

TEST(FuzzRegressions, TwoFileInputsSplitAtTheFirstNul) {
  using namespace std::string_literals;
  EXPECT_EQ(FirstPart("a: 1\0P5 x\0y"s), "a: 1");
  EXPECT_EQ(SecondPart("a: 1\0P5 x\0y"s), "P5 x\0y"s);
  EXPECT_EQ(FirstPart("no nul"), "no nul");
  EXPECT_EQ(SecondPart("no nul"), "");
}

TEST(FuzzRegressions, AValidFileIsAcceptedAndAnInvalidOneRejected) {
  const ReaderEntry* tum = FindReaderEntry("tum");
  ASSERT_NE(tum, nullptr);
  EXPECT_EQ(RunReaderEntry(*tum, "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n").outcome,
            ReaderOutcome::kAccepted);
  const ReaderResult short_line = RunReaderEntry(*tum, "1.0 0 0 0 0 0 0\n");
  EXPECT_EQ(short_line.outcome, ReaderOutcome::kRejected);
  EXPECT_NE(short_line.message.find("input.tum:1"), std::string::npos) << short_line.message;
  EXPECT_EQ(FindReaderEntry("no_such_reader"), nullptr);
}

}  // namespace
}  // namespace slamrig::fuzz
