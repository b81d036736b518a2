// The names `expect:` accepts per configuration are the metrics the run gives it: the general
// ones and exactly the statistics its estimator declares (and reports, statistics_test.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include "scenarios/scenario_spec.h"
#include "slam/pipeline/algorithm.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

// A log scenario of one configuration `c` of `algorithm` with `expect` as its expectations.
std::string WriteScenario(const std::string& algorithm, const std::string& expect) {
  const std::string dir = ::testing::TempDir() + "/expect_" + algorithm;
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/run.log") << "";
  const std::string path = dir + "/s.yaml";
  std::ofstream(path) << "source: {log: run.log}\nslam:\n  c: {algorithm: " << algorithm
                      << "}\nexpect:\n  c: {" << expect << "}\n";
  return path;
}

TEST(ExpectationNamesTest, EveryDeclaredStatisticIsAnExpectationAndNothingElse) {
  std::set<std::string> general(KnownMetrics().begin(), KnownMetrics().end());
  general.insert(LoopMetrics().begin(), LoopMetrics().end());
  general.insert(LandmarkMetrics().begin(), LandmarkMetrics().end());
  for (const slam::Algorithm& a : slam::Algorithms()) {
    if (!a.statistics_declared) continue;
    // An estimator that judges itself (declares `diverged`) has its lost intervals as well.
    const bool judges = std::count(a.statistics.begin(), a.statistics.end(), "diverged") == 1;
    std::set<std::string> rest;
    for (const std::string& m : MetricsOf(slam::DefaultEstimatorConfig("c", a.name)))
      if (!general.count(m) &&
          !(judges && std::count(HealthMetrics().begin(), HealthMetrics().end(), m) == 1))
        rest.insert(m);
    EXPECT_EQ(rest, std::set<std::string>(a.statistics.begin(), a.statistics.end())) << a.name;
    if (a.statistics.empty()) continue;
    std::string expect;
    for (const std::string& s : a.statistics)
      expect += (expect.empty() ? "" : ", ") + s + "_max: 1e9, " + s + "_min: -1e9";
    const ScenarioSpec spec = LoadScenario(WriteScenario(a.name, expect));
    EXPECT_EQ(spec.expectations.size(), 2 * a.statistics.size()) << a.name;
  }
}

TEST(ExpectationNamesTest, GraphInconsistentIsAcceptedAndLoopsOnlyWhereThereAreLoops) {
  EXPECT_EQ(LoadScenario(WriteScenario("graph", "inconsistent_max: 0")).expectations.size(), 1u);
  EXPECT_EQ(LoadScenario(WriteScenario("graph", "loop_precision_min: 0.9")).expectations.size(),
            1u);
  try {
    LoadScenario(WriteScenario("dead-reckoning", "loop_precision_min: 0.9"));
    ADD_FAILURE() << "dead reckoning closes no loops";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown expectation"), std::string::npos) << e.what();
  }
}

// Every estimator but dead reckoning (which cannot judge itself) may be held to never being lost.
TEST(ExpectationNamesTest, LostIsAnExpectationOfEveryEstimatorThatJudgesItself) {
  for (const std::string algorithm : {"pf", "rbpf", "graph", "icp-odometry", "ekf", "ekf-slam"}) {
    EXPECT_EQ(LoadScenario(WriteScenario(algorithm,
                                         "lost_max: 0, diverged_max: 0, lost_intervals_max: 0, "
                                         "lost_s_max: 0"))
                  .expectations.size(),
              4u)
        << algorithm;
  }
  for (const std::string expect : {"lost_max: 0", "diverged_max: 0", "lost_s_max: 0"}) {
    try {
      LoadScenario(WriteScenario("dead-reckoning", expect));
      ADD_FAILURE() << "dead reckoning does not judge itself: " << expect;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("unknown expectation"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace slamrig::scenario
