// Every estimator declares its statistics once (StatisticNames() beside Statistics()); the
// algorithm table, and so the expectations, use that list, and a run reports exactly it.
#include <gtest/gtest.h>

#include <set>

#include "slam/pf/testing/synthetic_run.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator_runner.h"

namespace slamrig::slam {
namespace {

std::set<std::string> Keys(const std::map<std::string, double>& statistics) {
  std::set<std::string> keys;
  for (const auto& [name, value] : statistics) keys.insert(name);
  return keys;
}

// Ten scans of a small synthetic office run through each algorithm (the Python one's statistics
// are whatever its class reports: it declares none).
TEST(StatisticsTest, EveryAlgorithmReportsExactlyTheStatisticsItDeclares) {
  RunLimits limits;
  limits.max_scans = 10;
  for (const Algorithm& a : Algorithms()) {
    if (!a.statistics_declared) continue;
    const EstimatorConfig config = DefaultEstimatorConfig(a.name, a.name);
    // Before any scan, too: a freshly made estimator.
    EXPECT_EQ(Keys(MakeEstimator(config, 1)->Statistics()),
              std::set<std::string>(a.statistics.begin(), a.statistics.end()))
        << a.name;
    const EstimatorRun run = RunEstimator(config, testing::SmallOfficeRecords(), 1, limits);
    EXPECT_EQ(run.online.size(), 10u) << a.name;
    EXPECT_EQ(Keys(run.statistics), std::set<std::string>(a.statistics.begin(), a.statistics.end()))
        << a.name;
    EXPECT_EQ(std::set<std::string>(a.statistics.begin(), a.statistics.end()).size(),
              a.statistics.size())
        << a.name << ": a name declared twice";
  }
  EXPECT_FALSE(FindAlgorithm("python")->statistics_declared);
  // Only the in-process C++ estimators run on threads of their own beside one another.
  for (const Algorithm& a : Algorithms()) {
    EXPECT_EQ(a.runs_beside_others, a.name != "python" && a.name != "external") << a.name;
  }
}

}  // namespace
}  // namespace slamrig::slam
