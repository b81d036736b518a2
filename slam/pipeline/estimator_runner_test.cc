#include "slam/pipeline/estimator_runner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "slam/pf/testing/synthetic_run.h"
#include "slam/pipeline/particle_filter_estimator.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

const std::vector<Record>& Records() { return testing::SmallOfficeRecords(); }

EstimatorConfig SmallPf() {
  EstimatorConfig config = DefaultEstimatorConfig("pf", "pf");
  ReadEstimatorFields(YamlNode::LoadString("particles: 20", "test"), &config);
  return config;
}

// The streaming runner (records one at a time, as a simulator delivers them) and the estimator
// fed the whole log's synchronised scans by hand give the same bits.
TEST(EstimatorRunnerTest, StreamingEqualsTheWholeLogByHand) {
  const EstimatorConfig config = SmallPf();
  const EstimatorRun streamed = RunEstimator(config, Records(), 7);

  const ScanSyncResult synced = SyncToScans(Records(), config.odometry);
  std::unique_ptr<Estimator> estimator = MakeEstimator(config, 7);
  ASSERT_EQ(streamed.online.size(), synced.scans.size());
  for (std::size_t i = 0; i < synced.scans.size(); ++i) {
    const ScanEstimate e = estimator->AddScan(synced.scans[i]);
    ASSERT_EQ(streamed.online[i].pose, e.pose) << i;
    ASSERT_EQ(streamed.online[i].time, synced.scans[i].scan.time) << i;
  }
  EXPECT_EQ(streamed.map.DenseLogOdds(), estimator->map().DenseLogOdds());
  EXPECT_EQ(streamed.traces.at("neff").size(), synced.scans.size());
  EXPECT_EQ(streamed.statistics.count("mean_neff"), 1u);
}

TEST(EstimatorRunnerTest, SeedsAreNamedStreamsOfTheRunSeed) {
  EstimatorConfig a = SmallPf();
  EstimatorConfig b = a;
  b.name = "other";
  const EstimatorRun ra = RunEstimator(a, Records(), 3);
  const EstimatorRun rb = RunEstimator(b, Records(), 3);
  const EstimatorRun ra2 = RunEstimator(a, Records(), 3);
  EXPECT_EQ(ra.final.poses().back().pose, ra2.final.poses().back().pose);
  EXPECT_NE(ra.final.poses().back().pose, rb.final.poses().back().pose);
}

TEST(EstimatorRunnerTest, MaxScansStopsThere) {
  RunLimits limits;
  limits.max_scans = 25;
  const EstimatorRun run =
      RunEstimator(DefaultEstimatorConfig("dr", "dead-reckoning"), Records(), 1, limits);
  EXPECT_EQ(run.online.size(), 25u);
}

TEST(EstimatorConfigTest, ReadsWritesAndRereadsEveryField) {
  const YamlNode node = YamlNode::LoadString(
      "algorithm: pf\npreset: reports\nparticles: 33\nrefiner: {max_iterations: 4}\n"
      "odometry: {use_gyro: false}\nmap: {resolution_m: 0.1}\n",
      "cfg.yaml");
  const EstimatorConfig config = ParseEstimatorConfig("mine", node);
  node.CheckAllKeysUsed();
  YAML::Emitter out;
  WriteEstimatorConfig(config, &out);
  const YamlNode again = YamlNode::LoadString(out.c_str(), "again.yaml");
  const EstimatorConfig reread = ParseEstimatorConfig("mine", again);
  again.CheckAllKeysUsed();
  YAML::Emitter out2;
  WriteEstimatorConfig(reread, &out2);
  EXPECT_EQ(std::string(out.c_str()), std::string(out2.c_str()));
  EXPECT_THAT(out.c_str(), ::testing::HasSubstr("particles: 33"));
  EXPECT_THAT(out.c_str(), ::testing::HasSubstr("motion_noise: gaussian"));  // the preset's
  EXPECT_FALSE(reread.odometry.use_gyro);
  JsonWriter json;
  WriteEstimatorConfigJson(config, &json);
  EXPECT_THAT(json.Finish(), ::testing::HasSubstr("\"particles\": 33"));
}

// The error reading `text` (file "s.yaml") as the estimator configuration `name` gives, or
// "no error".
std::string ConfigErrorOf(const std::string& text, const std::string& name) {
  try {
    const YamlNode node = YamlNode::LoadString(text, "s.yaml");
    ParseEstimatorConfig(name, node);
    node.CheckAllKeysUsed();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(EstimatorConfigTest, ErrorsNameFileLineAndKey) {
  const auto error = [](const std::string& text) { return ConfigErrorOf(text, "pf"); };
  EXPECT_THAT(error("algorithm: nope\n"), ::testing::HasSubstr("s.yaml:1:"));
  EXPECT_THAT(error("algorithm: nope\n"), ::testing::HasSubstr("unknown algorithm 'nope'"));
  EXPECT_THAT(error("algorithm: pf\nparticles: 0\n"), ::testing::HasSubstr("particles = 0"));
  EXPECT_THAT(error("algorithm: pf\nparticle: 3\n"), ::testing::HasSubstr("particle"));
  EXPECT_THAT(error("algorithm: pf\nmotion_noise: wild\n"),
              ::testing::HasSubstr("s.yaml:2:15: motion_noise: 'wild' is not one of"));
  EXPECT_THAT(error("algorithm: pf\npreset: fast\n"), ::testing::HasSubstr("unknown preset"));
  EXPECT_THAT(error("algorithm: pf\ncorrelation: {xy_half_width_cells: 99}\n"),
              ::testing::HasSubstr("correlation.xy_half_width_cells = 99"));
}

// Each options struct names its keys relative to itself; the reader adds the path once, however
// deep the struct sits (a struct that named itself too would read "odometry_icp.icp.icp."), and
// the error points at the broken value.
TEST(EstimatorConfigTest, ANestedStructsBrokenRuleIsNamedByItsPathOnce) {
  const auto error = [](const std::string& text) { return ConfigErrorOf(text, "e"); };
  EXPECT_EQ(error("algorithm: graph\nodometry_icp:\n  icp: {trim_fraction: 2}\n"),
            "s.yaml:3:24: odometry_icp.icp.trim_fraction = 2; must be in (0, 1]");
  EXPECT_EQ(error("algorithm: graph\nodometry_icp: {local_map_keyframes: 0}\n"),
            "s.yaml:2:37: odometry_icp.local_map_keyframes = 0; must be >= 1");
  EXPECT_EQ(error("algorithm: graph\nloop_icp: {trim_fraction: 2}\n"),
            "s.yaml:2:27: loop_icp.trim_fraction = 2; must be in (0, 1]");
  EXPECT_EQ(error("algorithm: graph\ncorrelative: {linear_window_m: -1}\n"),
            "s.yaml:2:32: correlative.linear_window_m = -1; must be >= 0");
  EXPECT_EQ(error("algorithm: graph\noptimizer: {max_iterations: 0}\n"),
            "s.yaml:2:29: optimizer.max_iterations = 0; must be >= 1");
  EXPECT_EQ(error("algorithm: icp-odometry\nicp: {max_iterations: 0}\n"),
            "s.yaml:2:23: icp.max_iterations = 0; must be >= 1");
  EXPECT_EQ(error("algorithm: icp-odometry\nlocal_map_keyframes: 0\n"),
            "s.yaml:2:22: local_map_keyframes = 0; must be >= 1");
}

}  // namespace
}  // namespace slamrig::slam
