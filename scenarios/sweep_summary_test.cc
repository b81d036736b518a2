#include "scenarios/sweep_summary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "tests/util/temp_dir.h"

namespace slamrig::scenario {
namespace {

using ::testing::HasSubstr;

// Two swept parameters (2 x 3 values), one held at one value, two seeds.
SweepSpec Grid() {
  SweepSpec spec;
  spec.scenario_path = "scenario.yaml";
  spec.seeds = {7, 9};
  spec.parameters = {{"a", {"1", "2"}, {}}, {"held", {"x"}, {}}, {"b", {"10", "20", "30"}, {}}};
  return spec;
}

const std::vector<std::string> kHeader = {"run",  "a",      "held", "b",
                                          "seed", "status", "m",    "wall_time_s"};

std::vector<std::string> Row(const std::string& a, const std::string& b, int seed,
                             const std::string& status, const std::string& m) {
  return {"a=" + a + " held=x b=" + b + " seed=" + std::to_string(seed),
          a,
          "x",
          b,
          std::to_string(seed),
          status,
          m,
          "1.5"};
}

TEST(SweepSummaryTest, GroupsRowsByGridPointWithTheSweptAxesOnly) {
  const std::vector<std::vector<std::string>> rows = {
      Row("1", "10", 7, "pass", "1"),
      Row("1", "10", 9, "fail", "3"),
      Row("2", "30", 9, "error", ""),
      Row("2", "30", 7, "pass", "0.5"),
      Row("3", "10", 7, "pass", "9"),  // a value not in the grid: skipped
      {"short", "row"}};
  // Grid row of (a=1, b=10, seed 9): point 0, seed index 1.
  const std::map<std::size_t, std::vector<ExpectationResult>> expectations = {
      {1, {{"s.m_max", 3.0, 2.0, false}, {"s.n_min", 1.0, 0.5, true}}},
      {0, {{"s.m_max", 1.0, 2.0, false}}}};  // a passed run's: not listed
  const SweepAggregate a = AggregateSweep(Grid(), kHeader, rows, expectations);
  EXPECT_EQ(a.swept, (std::vector<std::size_t>{0, 2}));
  EXPECT_EQ(a.metrics, (std::vector<std::string>{"m"}));
  ASSERT_EQ(a.points.size(), 6u);
  EXPECT_EQ(a.passed, 2);
  EXPECT_EQ(a.failed, 1);
  EXPECT_EQ(a.errors, 1);
  EXPECT_EQ(a.missing, 8);
  const GridPoint& first = a.points[0];
  EXPECT_EQ(first.value_index, (std::vector<std::size_t>{0, 0, 0}));
  ASSERT_EQ(first.seeds.size(), 2u);
  EXPECT_EQ(first.seeds[0].status, "pass");
  EXPECT_EQ(first.seeds[0].run_index, 0u);
  EXPECT_TRUE(first.seeds[0].failed.empty());
  EXPECT_EQ(first.seeds[1].status, "fail");
  EXPECT_EQ(first.seeds[1].run_index, 1u);
  ASSERT_EQ(first.seeds[1].failed.size(), 1u);
  EXPECT_EQ(first.seeds[1].failed[0].name, "s.m_max");
  EXPECT_EQ(first.seeds[1].failed[0].value, 3.0);
  EXPECT_EQ(first.metrics.at("m").mean, 2.0);
  EXPECT_EQ(first.metrics.at("m").min, 1.0);
  EXPECT_EQ(first.metrics.at("m").max, 3.0);
  const GridPoint& last = a.points[5];  // a=2, b=30: the error row has no value
  EXPECT_EQ(last.seeds[0].status, "pass");
  EXPECT_EQ(last.seeds[0].run_index, 10u);
  EXPECT_EQ(last.seeds[1].status, "error");
  EXPECT_EQ(last.metrics.at("m").count, 1);
  EXPECT_EQ(last.metrics.at("m").mean, 0.5);
  EXPECT_TRUE(a.points[3].metrics.empty());  // not run
}

// Over random results: each point's mean, min and max are those of its rows, computed here
// independently, and every row lands in exactly one seed of one point.
TEST(SweepSummaryTest, StatisticsMatchAnIndependentComputationOverRandomResults) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> value(0.0, 10.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<std::vector<std::string>> rows;
    std::map<std::pair<std::string, std::string>, std::vector<double>> expected;
    int kept = 0;
    for (const char* a : {"1", "2"}) {
      for (const char* b : {"10", "20", "30"}) {
        for (const int seed : {7, 9}) {
          if (rng() % 3 == 0) continue;
          const double v = std::round(value(rng) * 1000) / 1000;
          char text[32];
          std::snprintf(text, sizeof(text), "%.3f", v);
          rows.push_back(Row(a, b, seed, "pass", text));
          expected[{a, b}].push_back(std::stod(text));
          ++kept;
        }
      }
    }
    const SweepAggregate agg = AggregateSweep(Grid(), kHeader, rows, {});
    EXPECT_EQ(agg.passed, kept);
    EXPECT_EQ(agg.missing, 12 - kept);
    for (const GridPoint& p : agg.points) {
      const auto key = std::make_pair(Grid().parameters[0].values[p.value_index[0]],
                                      Grid().parameters[2].values[p.value_index[2]]);
      const auto it = expected.find(key);
      if (it == expected.end()) {
        EXPECT_TRUE(p.metrics.empty());
        continue;
      }
      double sum = 0;
      for (const double v : it->second) sum += v;
      const MetricStats& s = p.metrics.at("m");
      EXPECT_EQ(s.count, static_cast<int>(it->second.size()));
      EXPECT_NEAR(s.mean, sum / static_cast<double>(it->second.size()), 1e-12);
      EXPECT_EQ(s.min, *std::min_element(it->second.begin(), it->second.end()));
      EXPECT_EQ(s.max, *std::max_element(it->second.begin(), it->second.end()));
    }
  }
}

TEST(SweepSummaryTest, ReadsARunsExpectationsFromItsMetricsJson) {
  testing::TempDir dir;
  const std::string path = dir.Write(
      "metrics.json",
      "{\"passed\": false, \"expectations\": {\"pf.ate_rmse_m_max\": {\"threshold\": 0.1, "
      "\"value\": 0.25, \"passed\": false}, \"pf.map_f1_min\": {\"threshold\": 0.7, "
      "\"value\": null, \"passed\": false}}}");
  const std::vector<ExpectationResult> e = ReadRunExpectations(path);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].name, "pf.ate_rmse_m_max");
  EXPECT_EQ(e[0].value, 0.25);
  EXPECT_EQ(e[0].threshold, 0.1);
  EXPECT_FALSE(e[0].passed);
  EXPECT_TRUE(std::isnan(e[1].value));
  EXPECT_TRUE(ReadRunExpectations(dir.File("missing.json")).empty());
  EXPECT_TRUE(ReadRunExpectations(dir.Write("bad.json", "{\"expectations\": [")).empty());
}

// The page: a table row per grid point with each seed's verdict linked to its report and the
// failed expectation with value and bound; a heat map for the two swept parameters and no plot
// of the held one.
TEST(SweepSummaryTest, SummaryTableLinksEachRunAndNamesWhatFailed) {
  testing::TempDir dir;
  const SweepSpec spec = Grid();
  std::filesystem::create_directories(dir.File("out/runs/0001"));
  dir.Write("out/runs/0001/metrics.json",
            "{\"expectations\": {\"s.m_max\": {\"threshold\": 2, \"value\": 3, \"passed\": "
            "false}}}");
  std::string csv;
  for (const auto& row : std::vector<std::vector<std::string>>{
           kHeader, Row("1", "10", 7, "pass", "1"), Row("1", "10", 9, "fail", "3")}) {
    csv += JoinCsv(row) + "\n";
  }
  dir.Write("out/results.csv", csv);
  EXPECT_EQ(WriteSweepSummary(spec, dir.File("out")), 0);  // a heat map is HTML, not a PNG
  std::ifstream in(dir.File("out/summary.html"));
  const std::string html{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_THAT(html, HasSubstr("<tr><td>a=1, b=10</td><td class=\"pass\"><a "
                              "href=\"runs/0000/report.html\">pass</a></td><td class=\"fail\"><a "
                              "href=\"runs/0001/report.html\">FAIL</a></td>"));
  EXPECT_THAT(html, HasSubstr("<li>seed 9: s.m = 3, bound &le; 2</li>"));
  EXPECT_THAT(html, HasSubstr("<tr><td>a=2, b=30</td><td class=\"none\">not run</td>"));
  EXPECT_THAT(html, HasSubstr("<table class=\"heat\">"));
  EXPECT_THAT(html, HasSubstr("held: held = x"));
  EXPECT_THAT(html, ::testing::Not(HasSubstr("<img")));
}

}  // namespace
}  // namespace slamrig::scenario
