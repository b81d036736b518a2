#include "scenarios/sweep_runner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "slam/types/error.h"
#include "slam/types/thread_pool.h"
#include "tests/util/scoped_env.h"
#include "tests/util/temp_dir.h"

namespace slamrig::scenario {
namespace {

// A stand-in for `slamrig run`: writes a metrics.json whose value depends on the seed and the
// swept values only, like a deterministic run.
constexpr const char* kFakeRunner = R"(#!/bin/sh
out=""; seed=0; sum=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2;;
    --seed) seed="$2"; shift 2;;
    --set) v="${2#*=}"; sum="$sum+$v"; shift 2;;
    *) shift;;
  esac
done
value=$(awk "BEGIN { print $sum + $seed / 100 }")
printf '{"passed": true, "configs": {"pf": {"ate_rmse_m": %s, "name": "pf"}}}\n' "$value" > "$out/metrics.json"
)";

struct Fixture {
  testing::TempDir dir;
  SweepSpec spec;
  RunQueueOptions options;
  Fixture() {
    const std::string runner = dir.Write("fake_runner.sh", kFakeRunner);
    ::chmod(runner.c_str(), 0755);
    dir.Write("scenario.yaml", "name: x\n");
    spec = LoadSweepSpec(dir.Write("sweep.yaml",
                                   "scenario: scenario.yaml\nseeds: 3\nparameters:\n"
                                   "  a.noise: [1, 2]\n  b.count: [10, 20, 30]\n"
                                   "metrics: [pf.ate_rmse_m]\n"));
    options.out_dir = dir.File("out");
    options.slamrig_binary = runner;
    options.jobs = 2;
    options.progress = false;
  }
  std::vector<std::string> Lines() const {
    std::ifstream in(dir.File("out/results.csv"));
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    return lines;
  }
};

// A row without its wall-time column, the one field allowed to differ between runs.
std::string WithoutWallTime(const std::string& row) { return row.substr(0, row.rfind(',')); }

TEST(SweepTest, ExpandsTheGridTimesSeedsInAFixedOrder) {
  Fixture f;
  const auto runs = ExpandSweep(f.spec);
  ASSERT_EQ(runs.size(), 18u);
  EXPECT_EQ(runs.front().id, "a.noise=1 b.count=10 seed=1");
  EXPECT_EQ(runs[3].id, "a.noise=1 b.count=20 seed=1");
  EXPECT_EQ(runs.back().id, "a.noise=2 b.count=30 seed=3");
  std::set<std::string> ids;
  for (const auto& r : runs) ids.insert(r.id);
  EXPECT_EQ(ids.size(), runs.size());
}

TEST(SweepTest, RunsEveryRunOnceAndResumesAfterAKill) {
  Fixture complete;
  const RunQueueSummary all = RunSweep(complete.spec, complete.options);
  EXPECT_EQ(all.ran, 18);
  EXPECT_EQ(all.failed, 0);
  std::vector<std::string> expected = complete.Lines();
  ASSERT_EQ(expected.size(), 19u);
  EXPECT_EQ(expected[0], "run,a.noise,b.count,seed,status,pf.ate_rmse_m,wall_time_s");

  // A sweep killed after 7 rows, in the middle of writing the 8th.
  Fixture resumed;
  std::filesystem::create_directories(resumed.dir.File("out"));
  {
    std::ofstream out(resumed.dir.File("out/results.csv"));
    for (int i = 0; i < 8; ++i) out << expected[i] << "\n";
    out << expected[8].substr(0, 10);
  }
  const RunQueueSummary second = RunSweep(resumed.spec, resumed.options);
  EXPECT_EQ(second.already_done, 7);
  EXPECT_EQ(second.ran, 11);
  std::vector<std::string> got = resumed.Lines();
  ASSERT_EQ(got.size(), expected.size());
  std::multiset<std::string> a, b;
  for (const auto& l : expected) a.insert(WithoutWallTime(l));
  for (const auto& l : got) b.insert(WithoutWallTime(l));
  EXPECT_EQ(a, b);
  EXPECT_TRUE(std::filesystem::exists(resumed.dir.File("out/summary.html")));
  // Two swept parameters: a heat map per metric, no line plots.
  std::ifstream summary(resumed.dir.File("out/summary.html"));
  const std::string html{std::istreambuf_iterator<char>(summary), std::istreambuf_iterator<char>()};
  EXPECT_THAT(html, ::testing::HasSubstr("<table class=\"heat\">"));
  EXPECT_FALSE(std::filesystem::exists(resumed.dir.File("out/summary_pf.ate_rmse_m__a.noise.png")));
}

// Runs in parallel share the processors: each child's SLAMRIG_THREADS is its share (the default
// thread count of its estimators), unless the user set one; the rest of the environment passes.
TEST(SweepTest, ParallelRunsGetTheirShareOfTheProcessors) {
  const testing::ScopedEnv threads("SLAMRIG_THREADS", nullptr);
  const testing::ScopedEnv mark("SLAMRIG_SWEEP_TEST_MARK", "0.5");
  for (const bool user_set : {false, true}) {
    threads.Set(user_set ? "7" : nullptr);
    Fixture f;
    const std::string runner = f.dir.Write("threads_runner.sh", R"sh(#!/bin/sh
out=""
while [ $# -gt 0 ]; do
  case "$1" in --out) out="$2"; shift 2;; *) shift;; esac
done
printf '{"passed": true, "configs": {"pf": {"ate_rmse_m": %s, "name": "pf"}}}\n' \
  "$(awk "BEGIN { print $SLAMRIG_THREADS + $SLAMRIG_SWEEP_TEST_MARK }")" > "$out/metrics.json"
)sh");
    ::chmod(runner.c_str(), 0755);
    f.options.slamrig_binary = runner;
    f.options.jobs = 2;
    f.spec = LoadSweepSpec(f.dir.Write("two_runs.yaml",
                                       "scenario: scenario.yaml\nseeds: 2\nparameters:\n"
                                       "  a.noise: [1]\nmetrics: [pf.ate_rmse_m]\n"));
    EXPECT_EQ(RunSweep(f.spec, f.options).failed, 0);
    const int share = user_set ? 7 : std::max(1, slam::AvailableProcessors() / 2);
    const std::vector<std::string> lines = f.Lines();
    ASSERT_EQ(lines.size(), 3u);
    for (std::size_t k = 1; k < lines.size(); ++k) {
      EXPECT_THAT(lines[k], ::testing::HasSubstr(",pass," + std::to_string(share) + ".5,"))
          << lines[k];
    }
  }
}

// A sweep run again over a complete results.csv runs nothing and still counts the runs that
// failed before (its exit code says so).
TEST(SweepTest, AResumedSweepCountsTheRunsThatFailedBefore) {
  Fixture f;
  RunSweep(f.spec, f.options);
  std::vector<std::string> lines = f.Lines();
  ASSERT_EQ(lines.size(), 19u);
  for (const int i : {2, 5}) {
    lines[i].replace(lines[i].find(",pass,"), 6, i == 2 ? ",fail," : ",error,");
  }
  std::string csv;
  for (const auto& l : lines) csv += l + "\n";
  f.dir.Write("out/results.csv", csv);
  const RunQueueSummary again = RunSweep(f.spec, f.options);
  EXPECT_EQ(again.already_done, 18);
  EXPECT_EQ(again.ran, 0);
  EXPECT_EQ(again.failed, 2);
}

TEST(SweepTest, RefusesResultsOfAnotherSweep) {
  Fixture f;
  std::filesystem::create_directories(f.dir.File("out"));
  f.dir.Write("out/results.csv", "run,x,seed,status,pf.ate_rmse_m,wall_time_s\n");
  EXPECT_THROW(RunSweep(f.spec, f.options), ConfigError);
}

// A sweep of two seeds over `parameter` (a YAML entry) and `metrics` (a YAML list's items)
// whose results.csv is `results`: the summary it writes, and the number of plots.
struct SummaryRun {
  int plots = 0;
  std::string html;
};
SummaryRun SummarizeResults(testing::TempDir* dir, const std::string& parameter,
                            const std::string& metrics, const std::string& results) {
  dir->Write("scenario.yaml", "name: x\n");
  const SweepSpec spec =
      LoadSweepSpec(dir->Write("sweep.yaml", "scenario: scenario.yaml\nseeds: 2\nparameters:\n  " +
                                                 parameter + "\nmetrics: [" + metrics + "]\n"));
  std::filesystem::create_directories(dir->File("out"));
  dir->Write("out/results.csv", results);
  SummaryRun run;
  run.plots = WriteSweepSummary(spec, dir->File("out"));
  std::ifstream in(dir->File("out/summary.html"));
  run.html.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return run;
}

// The summary states each grid point's ANEES of a final_nees column with the chi-square region
// of its number of runs: here 2 runs of a.noise=1 (mean 2.5) and 1 of a.noise=2 (a NaN skipped).
TEST(SweepTest, SummaryShowsTheAneesWithItsChiSquareBounds) {
  testing::TempDir dir;
  const SummaryRun run =
      SummarizeResults(&dir, "a.noise: [1, 2]", "ekf.final_nees",
                       "run,a.noise,seed,status,ekf.final_nees,wall_time_s\n"
                       "r1,1,1,pass,2,1\nr2,1,2,pass,3,1\nr3,2,1,pass,40,1\nr4,2,2,error,,1\n");
  EXPECT_EQ(run.plots, 2);  // the metric's plot and the ANEES's
  const std::string& html = run.html;
  // chi2_6(0.025) / 2 = 1.2373 / 2, chi2_6(0.975) / 2 = 14.4494 / 2; chi2_3: 0.2158, 9.3484.
  EXPECT_THAT(html, ::testing::HasSubstr("<td>a.noise=1</td><td>2</td><td>2.500</td><td>0.619</td>"
                                         "<td>7.225</td><td>inside</td>"));
  EXPECT_THAT(html, ::testing::HasSubstr("<td>a.noise=2</td><td>1</td><td>40.000</td><td>0.216</td>"
                                         "<td>9.348</td><td>above (optimistic)</td>"));
  EXPECT_TRUE(std::filesystem::exists(dir.File("out/summary_anees_ekf.final_nees.png")));
}

// A landmark_anees column pools over the landmarks: each run's mean weighted by its
// pillars_mapped, the region that of all those landmarks' 2 dof. Here (2 * 10 + 5 * 5) / 15 = 3,
// against chi2_30(0.025) / 15 = 1.119 and chi2_30(0.975) / 15 = 3.132.
TEST(SweepTest, SummaryPoolsTheLandmarkAneesOverTheMappedLandmarks) {
  testing::TempDir dir;
  const std::string html =
      SummarizeResults(&dir, "a.noise: [1]", "s.landmark_anees, s.pillars_mapped",
                       "run,a.noise,seed,status,s.landmark_anees,s.pillars_mapped,wall_time_s\n"
                       "r1,1,1,pass,2,10,1\nr2,1,2,pass,5,5,1\n")
          .html;
  EXPECT_THAT(html, ::testing::HasSubstr("<td>a.noise=1</td><td>2</td><td>3.000</td><td>1.119</td>"
                                         "<td>3.132</td><td>inside</td>"));
  EXPECT_TRUE(std::filesystem::exists(dir.File("out/summary_anees_s.landmark_anees.png")));
}

// A bad value in the grid fails before any run or output, naming its place in the sweep file and
// the rule; two values valid alone but not together fail as their combination; a good grid
// passes. Over the shipped office scenario, which LoadScenario resolves for real.
TEST(SweepTest, CheckSweepGridNamesTheBadValueBeforeAnythingRuns) {
  testing::TempDir dir;
  const std::string office = std::string(SLAMRIG_SOURCE_DIR) + "/scenarios/office_loop.yaml";
  auto error = [&](const std::string& parameters) {
    try {
      CheckSweepGrid(LoadSweepSpec(dir.Write(
          "sweep.yaml", "scenario: " + office + "\nseeds: 2\nparameters:\n" + parameters)));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("  slam.pf.particles: [30, 100]\n  world.drive.laps: [1, 2]\n"), "");
  EXPECT_THAT(error("  world.drive.laps: [1]\n  slam.pf.particles: [30, 0]\n"),
              ::testing::MatchesRegex(".*sweep.yaml:5:[0-9]+: parameters.slam.pf.particles\\[1\\]: "
                                      "slam.pf.particles = 0; must be > 0"));
  EXPECT_THAT(error("  slam.pf.particles: [abc]\n"),
              ::testing::HasSubstr("sweep.yaml:4:23: parameters.slam.pf.particles[0]: "
                                   "slam.pf.particles: expected an integer, got 'abc'"));
  EXPECT_THAT(error("  slam.pf.relocalisation.slow_rate: [0.02, 0.5]\n"
                    "  slam.pf.relocalisation.fast_rate: [1.0, 0.3]\n"),
              ::testing::HasSubstr("sweep.yaml: parameters: the combination "
                                   "slam.pf.relocalisation.slow_rate=0.5 "
                                   "slam.pf.relocalisation.fast_rate=0.3: "
                                   "slam.pf.relocalisation.slow_rate = 0.5; must be <= fast_rate"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("out")));
}

TEST(SweepTest, BadSweepFilesNameFileLineAndKey) {
  testing::TempDir dir;
  dir.Write("s.yaml", "name: x\n");
  auto error = [&](const std::string& text) {
    try {
      LoadSweepSpec(dir.Write("sweep.yaml", text));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error("scenario: s.yaml\nseeds: 0\nparameters: {a: [1]}\n"),
              ::testing::HasSubstr("sweep.yaml:2:8: seeds"));
  EXPECT_THAT(error("scenario: nope.yaml\nseeds: 2\nparameters: {a: [1]}\n"),
              ::testing::HasSubstr("does not exist"));
  EXPECT_THAT(error("scenario: s.yaml\nseeds: 2\nparameters: {a: []}\n"),
              ::testing::HasSubstr("needs at least one value"));
  EXPECT_THAT(error("scenario: s.yaml\nseeds: 2\nparameters: {a: [1]}\nseed: 3\n"),
              ::testing::HasSubstr("sweep.yaml:4:1: seed: unknown key"));
  // Found while fuzzing sweep files: 100000 seeds x 100 x 100 values ran out of memory
  // (std::bad_alloc) in ExpandSweep. 1000 seeds x 1000 values is exactly the limit.
  std::string hundred, thousand;
  for (int i = 0; i < 1000; ++i) {
    if (i < 100) hundred += (i ? "," : "") + std::to_string(i);
    thousand += (i ? "," : "") + std::to_string(i);
  }
  EXPECT_THAT(error("scenario: s.yaml\nseeds: 100000\nparameters:\n  a: [" + hundred + "]\n  b: [" +
                    hundred + "]\n"),
              ::testing::HasSubstr("sweep.yaml:4:3: parameters: seeds x parameter values is more "
                                   "than 1000000 runs"));
  EXPECT_EQ(error("scenario: s.yaml\nseeds: 1000\nparameters:\n  a: [" + thousand + "]\n"), "");
  // Found by fuzz/ (scenario_yaml target): a file name longer than the OS allows made
  // std::filesystem::exists throw filesystem_error (ENAMETOOLONG) instead of a ConfigError.
  EXPECT_THAT(error("scenario: " + std::string(5000, 'x') + "\nseeds: 2\nparameters: {a: [1]}\n"),
              ::testing::HasSubstr("sweep.yaml:1:11: scenario: scenario file"));
}

}  // namespace
}  // namespace slamrig::scenario
