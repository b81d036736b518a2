#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "scenarios/benchmark_runner.h"
#include "scenarios/benchmark_spec.h"
#include "scenarios/benchmark_summary.h"
#include "scenarios/scenario_spec.h"
#include "slam/types/error.h"
#include "tests/util/temp_dir.h"

namespace slamrig::scenario {
namespace {

// A suite of small generated offices (cheap to resolve) with two estimators.
constexpr char kSuite[] = R"(timeout_s: 60
estimators:
  pf: {algorithm: pf, particles: 20}
  graph: {algorithm: graph}
datasets:
  - name: small
    generate: {kind: office, width_m: 24, height_m: 18}
    seeds: {from: 3, to: 5}
    duration_s: 20
  - name: other
    generate: {kind: maze, width_m: 20, height_m: 20}
    seeds: [9]
)";

std::string ErrorOf(const std::string& text) {
  testing::TempDir dir;
  try {
    LoadBenchmarkSuite(dir.Write("suite.yaml", text));
  } catch (const ConfigError& e) {
    std::string what = e.what();
    const std::size_t name = what.find("suite.yaml");
    return name == std::string::npos ? what : what.substr(name);
  }
  return "";
}

// Run `run` of `suite`'s scenario, written into `dir` as `file` and read back.
ScenarioSpec RunScenario(const testing::TempDir& dir, const std::string& file,
                         const BenchmarkSuite& suite, const BenchmarkRun& run) {
  return LoadScenario(dir.Write(file, BenchmarkScenarioYaml(suite, run)));
}

TEST(BenchmarkSpecTest, ExpandsDatasetsSeedsAndEstimatorsInFileOrder) {
  testing::TempDir dir;
  const BenchmarkSuite suite = LoadBenchmarkSuite(dir.Write("suite.yaml", kSuite));
  EXPECT_EQ(suite.timeout_s, 60.0);
  const std::vector<BenchmarkRun> runs = ExpandBenchmark(suite);
  ASSERT_EQ(runs.size(), 8u);  // (3 + 1) seeds x 2 estimators
  EXPECT_EQ(runs[0].id, "small seed=3 pf");
  EXPECT_EQ(runs[1].id, "small seed=3 graph");
  EXPECT_EQ(runs[5].id, "small seed=5 graph");
  EXPECT_EQ(runs[6].id, "other seed=9 pf");
  EXPECT_EQ(runs[7].seed, 9u);
}

TEST(BenchmarkSpecTest, EachRunIsAScenarioWithItsSeedItsEstimatorAndTheBaseline) {
  testing::TempDir dir;
  const BenchmarkSuite suite = LoadBenchmarkSuite(dir.Write("suite.yaml", kSuite));
  const std::vector<BenchmarkRun> runs = ExpandBenchmark(suite);
  const ScenarioSpec scenario =
      RunScenario(dir, "run.yaml", suite, runs[3]);  // small, seed 4, graph
  EXPECT_EQ(scenario.seed, 4u);
  EXPECT_EQ(scenario.duration_s, 20.0);
  ASSERT_TRUE(scenario.simulated.has_value());
  ASSERT_EQ(scenario.configs.size(), 2u);
  EXPECT_EQ(scenario.configs[0].name, kBaselineName);
  EXPECT_EQ(scenario.configs[0].algorithm, "dead-reckoning");
  EXPECT_EQ(scenario.configs[1].name, "graph");
  EXPECT_TRUE(scenario.expectations.empty());
  // The world is the dataset's at the run's seed: another seed gives another world.
  const ScenarioSpec other = RunScenario(dir, "other.yaml", suite, runs[1]);
  EXPECT_NE(scenario.simulated->options.world.walls.size() +
                1000 * scenario.simulated->options.world.drive.waypoints_m.size(),
            other.simulated->options.world.walls.size() +
                1000 * other.simulated->options.world.drive.waypoints_m.size());
}

TEST(BenchmarkSpecTest, AWorldFileIsTheSameWorldAtEverySeedWithItsOverrides) {
  testing::TempDir dir;
  const std::string world = std::string(SLAMRIG_SOURCE_DIR) + "/worlds/two_rooms.yaml";
  const BenchmarkSuite suite =
      LoadBenchmarkSuite(dir.Write("suite.yaml",
                                   "estimators:\n  mine: {algorithm: external, command: [python3, "
                                   "./client.py, \"{input}\", \"{output}\"]}\ndatasets:\n"
                                   "  - name: rooms\n    world: " +
                                       world +
                                       "\n    world_overrides: {drive.laps: 2}\n"
                                       "    seeds: [1, 2]\n    duration_s: 30\n"));
  const std::vector<BenchmarkRun> runs = ExpandBenchmark(suite);
  ASSERT_EQ(runs.size(), 2u);
  const std::string text = BenchmarkScenarioYaml(suite, runs[0]);
  const ScenarioSpec one = LoadScenario(dir.Write("run_a.yaml", text));
  const ScenarioSpec two = RunScenario(dir, "run_b.yaml", suite, runs[1]);
  ASSERT_TRUE(one.simulated.has_value() && two.simulated.has_value());
  EXPECT_EQ(one.seed, 1u);
  EXPECT_EQ(two.seed, 2u);
  EXPECT_EQ(one.simulated->options.world.name, "two_rooms");
  EXPECT_EQ(one.simulated->options.world.walls.size(), two.simulated->options.world.walls.size());
  EXPECT_EQ(one.simulated->options.world.drive.laps, 2);
  // The run's scenario is in another folder: the program is the one beside the suite.
  EXPECT_NE(text.find((dir.path() / "client.py").string()), std::string::npos) << text;
  EXPECT_NE(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    world: no/such.yaml\n")
                .find("datasets[0].world: no world file"),
            std::string::npos);
  EXPECT_NE(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    world: a.yaml\n    log: b.log\n")
                .find("needs exactly one of log:"),
            std::string::npos);
}

TEST(BenchmarkSpecTest, BadInputNamesTheFileLineAndKey) {
  EXPECT_EQ(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: ofice}\n"),
            "suite.yaml:4:22: datasets[0].generate.kind: unknown kind 'ofice'; expected one of "
            "office, warehouse, corridor, campus, maze");
  EXPECT_EQ(ErrorOf("estimators: {pf: {algorithm: pf, partcles: 3}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: office}\n"),
            "suite.yaml:1:34: estimators.pf.partcles: unknown key");
  EXPECT_EQ(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: maze}\n    seeds: {from: 5, to: 2}\n"),
            "suite.yaml:5:12: datasets[0].seeds: to (2) is below from (5)");
  EXPECT_NE(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: maze, seed: 3}\n")
                .find("datasets[0].generate.seed: the worlds' seeds are the dataset's seeds"),
            std::string::npos);
  EXPECT_NE(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: maze}\n  - name: x\n    generate: {kind: maze}\n")
                .find("dataset 'x' is named twice"),
            std::string::npos);
  EXPECT_NE(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    log: no/such.log\n")
                .find("datasets[0].log: no log 'no/such.log'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("estimators: {dead_reckoning: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: maze}\n")
                .find("its algorithm must be dead-reckoning"),
            std::string::npos);
  // Known only once the run's scenario is resolved: still named at the dataset.
  EXPECT_NE(ErrorOf("estimators: {pf: {algorithm: pf}}\ndatasets:\n  - name: x\n"
                    "    generate: {kind: maze}\n    robot_overrides: {lidar.range_maxx: 3}\n")
                .find("suite.yaml:3:5: datasets[0] (x, estimator pf): "),
            std::string::npos);
}

TEST(BenchmarkRunnerTest, FailsAboveTheSuitesBoundHoweverFarDeadReckoningIs) {
  std::string reason;
  BenchmarkFigures f;
  f.baseline_ate_rmse_m = 0.3;
  f.estimator["ate_rmse_m"] = 0.9;
  EXPECT_EQ(JudgeBenchmarkRun(f, 1.0, &reason), "pass");
  EXPECT_EQ(reason, "");
  f.estimator["ate_rmse_m"] = 1.1;
  EXPECT_EQ(JudgeBenchmarkRun(f, 1.0, &reason), "fail");
  EXPECT_EQ(reason, "ATE 1.1 m above 1 m (dead reckoning's 0.3 m)");
  // Far better than dead reckoning is still a failure above the bound.
  f.baseline_ate_rmse_m = 13.0;
  f.estimator["ate_rmse_m"] = 8.5;
  EXPECT_EQ(JudgeBenchmarkRun(f, 1.0, &reason), "fail");
  EXPECT_EQ(reason, "ATE 8.5 m above 1 m (dead reckoning's 13 m)");
  EXPECT_EQ(JudgeBenchmarkRun(f, 10.0, &reason), "pass");
  f.baseline_ate_rmse_m = -1.0;  // no baseline
  EXPECT_EQ(JudgeBenchmarkRun(f, 5.0, &reason), "fail");
  EXPECT_EQ(reason, "ATE 8.5 m above 5 m");
  f.estimator.clear();
  EXPECT_EQ(JudgeBenchmarkRun(f, 1.0, &reason), "fail");
  EXPECT_EQ(reason, "no ATE (no trajectory to score)");
}

TEST(BenchmarkSummaryTest, QuantilesInterpolateBetweenRanksAsNumpyDoes) {
  // numpy.quantile([1, 2, 4, 8, 16], [0, 0.5, 0.9, 1]) = [1, 4, 12.8, 16].
  const std::vector<double> v = {1, 2, 4, 8, 16};
  EXPECT_DOUBLE_EQ(Quantile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Quantile(v, 0.5), 4.0);
  EXPECT_DOUBLE_EQ(Quantile(v, 0.9), 12.8);
  EXPECT_DOUBLE_EQ(Quantile(v, 1.0), 16.0);
  EXPECT_DOUBLE_EQ(Quantile({7.0}, 0.9), 7.0);
  EXPECT_DOUBLE_EQ(Quantile({}, 0.5), 0.0);
}

TEST(BenchmarkSummaryTest, LeaderboardGroupsByEstimatorAndDatasetWithFailuresFirst) {
  testing::TempDir dir;
  const BenchmarkSuite suite = LoadBenchmarkSuite(dir.Write("suite.yaml", kSuite));
  const std::vector<std::string>& header = BenchmarkHeader();
  const auto diverged_col = static_cast<std::size_t>(
      std::find(header.begin(), header.end(), "diverged") - header.begin());
  ASSERT_LT(diverged_col, header.size());
  auto row = [&](const std::string& id, const std::string& status, const std::string& ate,
                 const std::string& diverged = "") {
    std::vector<std::string> r(header.size());
    r[0] = id;
    r[4] = status;
    r[5] = status == "pass" ? "" : "why";
    r[6] = ate;
    r[diverged_col] = diverged;
    return r;
  };
  const std::vector<std::vector<std::string>> rows = {
      row("small seed=3 pf", "pass", "0.1"),       row("small seed=4 pf", "pass", "0.3"),
      row("small seed=5 pf", "fail", "2.5"),       row("small seed=3 graph", "pass", "0.05"),
      row("small seed=4 graph", "fail", "3", "1"), row("small seed=5 graph", "timeout", ""),
      row("not in the suite", "pass", "9"),
  };
  const Leaderboard board = BuildLeaderboard(suite, header, rows);
  ASSERT_EQ(board.estimators, (std::vector<std::string>{"pf", "graph"}));
  ASSERT_EQ(board.datasets, (std::vector<std::string>{"small", "other"}));
  const LeaderboardCell& pf = board.cells[0][0];
  EXPECT_EQ(pf.runs, 3);
  EXPECT_EQ(pf.failures, 1);
  EXPECT_EQ(pf.silent, 1);  // pf gives no verdict: its failure is silent
  EXPECT_DOUBLE_EQ(pf.median, 0.3);
  EXPECT_DOUBLE_EQ(pf.p90, 0.3 + 0.8 * 2.2);
  EXPECT_DOUBLE_EQ(pf.max, 2.5);
  const LeaderboardCell& graph = board.cells[1][0];
  EXPECT_EQ(graph.runs, 3);
  EXPECT_EQ(graph.failures, 2);
  EXPECT_EQ(graph.silent, 1);  // the timeout; the other failure said it had diverged
  EXPECT_EQ(graph.ate, (std::vector<double>{0.05, 3.0}));
  EXPECT_EQ(board.cells[0][1].runs, 0);
  EXPECT_EQ(board.missing, 8 - 6);
  ASSERT_EQ(board.worst.size(), 6u);
  EXPECT_EQ(board.worst[0].id, "small seed=5 graph");  // failed without an ATE: the worst
  EXPECT_EQ(board.worst[1].id, "small seed=4 graph");  // failed, ATE 3
  EXPECT_EQ(board.worst[2].id, "small seed=5 pf");     // failed, ATE 2.5
  EXPECT_EQ(board.worst[3].id, "small seed=4 pf");     // passed, the largest ATE
}

}  // namespace
}  // namespace slamrig::scenario
