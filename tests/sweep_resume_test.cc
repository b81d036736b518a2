// A sweep killed with SIGKILL half way and started again ends with exactly the rows of an
// uninterrupted sweep (wall time aside), each run once.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <set>
#include <thread>

#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

std::vector<std::string> Rows(const std::string& csv) {
  std::ifstream in(csv);
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(line);
  return rows;
}

std::multiset<std::string> WithoutWallTime(const std::vector<std::string>& rows) {
  std::multiset<std::string> out;
  for (const auto& r : rows) out.insert(r.substr(0, r.rfind(',')));
  return out;
}

TEST(SweepResumeTest, KilledSweepResumesToTheSameRows) {
  testing::TempDir dir;
  // 2 parameters x 3 values x 5 seeds on a few seconds of the office scenario.
  const std::string sweep =
      dir.Write("sweep.yaml", std::string("scenario: ") + SLAMRIG_SOURCE_DIR +
                                  "/scenarios/office_loop.yaml\nseeds: 5\nparameters:\n"
                                  "  duration_s: [2, 3, 4]\n  slam.pf.particles: [5, 10, 20]\n");
  const std::string binary = SLAMRIG_BINARY;
  const auto full =
      testing::RunCommand(binary + " sweep " + sweep + " --out " + dir.File("full") + " --quiet");
  ASSERT_EQ(full.exit_code, 3) << full.output;  // the short runs miss the scenario's expectations
  const std::vector<std::string> expected = Rows(dir.File("full/results.csv"));
  ASSERT_EQ(expected.size(), 46u);

  // Start the same sweep elsewhere and kill it once about half of the rows are in.
  const std::string out = dir.File("killed");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl(binary.c_str(), binary.c_str(), "sweep", sweep.c_str(), "--out", out.c_str(), "--quiet",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (Rows(out + "/results.csv").size() < 23 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::size_t rows_at_kill = Rows(out + "/results.csv").size();
  EXPECT_GE(rows_at_kill, 23u);
  EXPECT_LT(rows_at_kill, expected.size()) << "the sweep finished before it could be killed";

  const auto resumed =
      testing::RunCommand(binary + " sweep " + sweep + " --out " + out + " --quiet");
  EXPECT_NE(resumed.output.find("from an earlier sweep"), std::string::npos) << resumed.output;
  const std::vector<std::string> got = Rows(out + "/results.csv");
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_EQ(WithoutWallTime(got), WithoutWallTime(expected));
}

}  // namespace
}  // namespace slamrig
