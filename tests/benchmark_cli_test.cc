// `slamrig benchmark` end to end on a suite of a few short runs: every pair runs, results.csv and
// summary.html are written, a second run of the same command resumes with nothing to do, the
// same suite elsewhere gives the same rows (time and memory aside), and a run past the suite's
// timeout is killed and recorded as such.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "scenarios/benchmark_spec.h"
#include "scenarios/sweep_summary.h"
#include "tests/util/dataset.h"
#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

std::vector<std::vector<std::string>> Rows(const std::string& csv) {
  std::ifstream in(csv);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(scenario::SplitCsv(line));
  return rows;
}

// The rows without the three machine-dependent columns at the end.
std::vector<std::vector<std::string>> WithoutTiming(std::vector<std::vector<std::string>> rows) {
  for (auto& r : rows) r.resize(r.size() >= 3 ? r.size() - 3 : 0);
  return rows;
}

std::string Suite(double timeout_s) {
  return "timeout_s: " + std::to_string(timeout_s) +
         "\nestimators:\n  pf: {algorithm: pf, particles: 20}\n  graph: {algorithm: graph}\n"
         "datasets:\n  - name: office\n    generate: {kind: office, width_m: 24, height_m: 18}\n"
         "    seeds: [1, 2]\n    duration_s: 20\n  - name: intel\n    log: " +
         (testing::DataDir() / "carmen_corrected/intel-corrected.log.gz").string() +
         "\n    max_scans: 80\n";
}

TEST(BenchmarkCliTest, RunsEveryPairResumesAndReproduces) {
  testing::TempDir dir;
  const std::string suite = dir.Write("suite.yaml", Suite(600));
  const std::string binary = SLAMRIG_BINARY;
  const auto first =
      testing::RunCommand(binary + " benchmark " + suite + " --out " + dir.File("a") + " --quiet");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const auto rows = Rows(dir.File("a/results.csv"));
  ASSERT_EQ(rows.size(), 1u + 6u);  // header, (2 offices + intel) x 2 estimators
  EXPECT_EQ(rows[0][0], "run");
  auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(rows[0].begin(), rows[0].end(), name) -
                                    rows[0].begin());
  };
  const std::size_t diverged = column("diverged"), baseline = column("dead_reckoning_ate_rmse_m"),
                    lost_s = column("lost_s");
  ASSERT_LT(diverged, rows[0].size());
  ASSERT_LT(lost_s, rows[0].size());
  ASSERT_LT(baseline, rows[0].size());
  for (std::size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i][4], "pass") << rows[i][0] << ": " << rows[i][5];
    EXPECT_FALSE(rows[i][6].empty()) << rows[i][0];         // an ATE
    EXPECT_FALSE(rows[i][baseline].empty()) << rows[i][0];  // dead reckoning's on the same data
    // Each estimator's own verdict: 0 on these clean runs; the seconds it said it was lost.
    EXPECT_EQ(rows[i][diverged], "0") << rows[i][0];
    EXPECT_FALSE(rows[i][lost_s].empty()) << rows[i][0];
  }
  const std::string summary = ReadFile(dir.File("a/summary.html"));
  EXPECT_NE(summary.find("Leaderboard"), std::string::npos);
  EXPECT_NE(summary.find("runs/0000/report.html"), std::string::npos);
  EXPECT_NE(ReadFile(dir.File("a/runs/0005/scenario.yaml")).find("max_scans: 80"),
            std::string::npos);

  const auto again =
      testing::RunCommand(binary + " benchmark " + suite + " --out " + dir.File("a") + " --quiet");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("6 runs (6 from an earlier benchmark, 0 now)"), std::string::npos)
      << again.output;
  EXPECT_EQ(Rows(dir.File("a/results.csv")).size(), rows.size());

  const auto elsewhere = testing::RunCommand(binary + " benchmark " + suite + " --out " +
                                             dir.File("b") + " --quiet --jobs 1");
  ASSERT_EQ(elsewhere.exit_code, 0) << elsewhere.output;
  EXPECT_EQ(WithoutTiming(Rows(dir.File("b/results.csv"))), WithoutTiming(rows));

  // The same folder with another suite is refused, not mixed.
  const std::string changed = dir.Write(
      "changed.yaml",
      std::string(Suite(600)).replace(Suite(600).find("particles: 20"), 13, "particles: 30"));
  const auto mixed = testing::RunCommand(binary + " benchmark " + changed + " --out " +
                                         dir.File("a") + " --quiet");
  EXPECT_EQ(mixed.exit_code, 2) << mixed.output;
  EXPECT_NE(mixed.output.find("written by another suite"), std::string::npos) << mixed.output;
}

TEST(BenchmarkCliTest, ARunPastTheTimeoutIsKilledAndFailed) {
  testing::TempDir dir;
  const std::string suite = dir.Write(
      "suite.yaml",
      "timeout_s: 0.5\nestimators:\n  rbpf: {algorithm: rbpf}\ndatasets:\n"
      "  - name: intel\n    log: " +
          (testing::DataDir() / "carmen_corrected/intel-corrected.log.gz").string() + "\n");
  const auto run = testing::RunCommand(std::string(SLAMRIG_BINARY) + " benchmark " + suite +
                                       " --out " + dir.File("out") + " --quiet");
  EXPECT_EQ(run.exit_code, 3) << run.output;
  const auto rows = Rows(dir.File("out/results.csv"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1][4], "timeout");
  EXPECT_EQ(rows[1][5], "still running after 0.5 s");
  EXPECT_NE(ReadFile(dir.File("out/summary.html")).find("timeout"), std::string::npos);
}

// Every shipped suite loads: its logs are there, its worlds generate, its estimators resolve.
TEST(BenchmarkCliTest, EveryShippedSuiteLoads) {
  int suites = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(SLAMRIG_SOURCE_DIR) + "/suites")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const scenario::BenchmarkSuite suite = scenario::LoadBenchmarkSuite(entry.path().string());
    EXPECT_FALSE(scenario::ExpandBenchmark(suite).empty());
    ++suites;
  }
  EXPECT_GE(suites, 4);
}

}  // namespace
}  // namespace slamrig
