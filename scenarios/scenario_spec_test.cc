#include "scenarios/scenario_spec.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

// A scenario file beside an (empty) log file, in the test's temporary folder.
std::string WriteScenario(const std::string& name, const std::string& source) {
  const std::string dir = testing::TempDir() + "/spec_" + name;
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/run.mcap") << "";
  const std::string path = dir + "/s.yaml";
  std::ofstream(path) << "name: " << name << "\nsource: " << source
                      << "\nslam:\n  dr: {algorithm: dead-reckoning}\n";
  return path;
}

std::string ErrorOf(const std::string& path) {
  try {
    LoadScenario(path);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ScenarioSpecTest, LogSourceTakesBagTopicNames) {
  const ScenarioSpec spec =
      LoadScenario(WriteScenario("topics", "{log: run.mcap, topics: {scan: /front/scan}}"));
  ASSERT_TRUE(spec.log);
  EXPECT_EQ(spec.log->read.topics.scan, "/front/scan");
  EXPECT_EQ(spec.log->read.topics.imu, slam::BagTopicNames{}.imu);  // the others: defaults
  // The resolved file names every topic, so that it repeats the run.
  EXPECT_NE(spec.resolved_yaml.find("scan: /front/scan"), std::string::npos) << spec.resolved_yaml;
  EXPECT_NE(spec.resolved_yaml.find("ground_truth: /ground_truth/odom"), std::string::npos);
}

TEST(ScenarioSpecTest, RecordIsReadAndRepeatedInTheResolvedFile) {
  const std::string path = WriteScenario("record", "{log: run.mcap}");
  EXPECT_FALSE(LoadScenario(path).record);
  std::ofstream(path, std::ios::app) << "record: true\n";
  const ScenarioSpec spec = LoadScenario(path);
  EXPECT_TRUE(spec.record);
  EXPECT_NE(spec.resolved_yaml.find("record: true"), std::string::npos) << spec.resolved_yaml;
  const std::string bad = WriteScenario("record_bad", "{log: run.mcap}");
  std::ofstream(bad, std::ios::app) << "record: maybe\n";
  const std::string error = ErrorOf(bad);
  EXPECT_NE(error.find("s.yaml:5:"), std::string::npos) << error;
  EXPECT_NE(error.find("record"), std::string::npos) << error;
}

TEST(ScenarioSpecTest, BadTopicNamesNameFileLineAndKey) {
  const std::string unknown = ErrorOf(WriteScenario("typo", "{log: run.mcap, topics: {scna: /x}}"));
  EXPECT_NE(unknown.find("s.yaml:2:"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("source.topics.scna: unknown topic key 'scna'"), std::string::npos)
      << unknown;
  const std::string relative = ErrorOf(WriteScenario("rel", "{log: run.mcap, topics: {imu: imu}}"));
  EXPECT_NE(relative.find("s.yaml:2:"), std::string::npos) << relative;
  EXPECT_NE(relative.find("topics.imu = 'imu'; must be an absolute ROS topic name"),
            std::string::npos)
      << relative;
  const std::string repeated =
      ErrorOf(WriteScenario("dup", "{log: run.mcap, topics: {imu: /scan}}"));
  EXPECT_NE(repeated.find("must differ from topics.scan"), std::string::npos) << repeated;
  const std::string not_map = ErrorOf(WriteScenario("list", "{log: run.mcap, topics: [/x]}"));
  EXPECT_NE(not_map.find("topics is a map"), std::string::npos) << not_map;
}

TEST(ScenarioSpecTest, LogSourceTakesAPerturbation) {
  const ScenarioSpec spec = LoadScenario(
      WriteScenario("perturb",
                    "{log: run.mcap, perturb: {odometry: {noise_per_m: 0.1, lost: [[5, 8]]}, "
                    "scans: {drop_fraction: 0.1}}}"));
  ASSERT_TRUE(spec.log);
  EXPECT_EQ(spec.log->perturb.odometry.noise_per_m, 0.1);
  ASSERT_EQ(spec.log->perturb.odometry.lost.size(), 1u);
  EXPECT_EQ(spec.log->perturb.scans.drop_fraction, 0.1);
  // The resolved file carries it, so that it repeats the run.
  const ScenarioSpec again = LoadScenario(WriteScenario("again", "{log: run.mcap}"));
  EXPECT_NE(spec.resolved_yaml.find("perturb:"), std::string::npos) << spec.resolved_yaml;
  EXPECT_NE(spec.resolved_yaml.find("drop_fraction: 0.1"), std::string::npos);
  EXPECT_EQ(again.resolved_yaml.find("perturb:"), std::string::npos) << again.resolved_yaml;

  const std::string unknown =
      ErrorOf(WriteScenario("ptypo", "{log: run.mcap, perturb: {scans: {dropfraction: 1}}}"));
  EXPECT_NE(unknown.find("s.yaml:2:"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("source.perturb.scans.dropfraction"), std::string::npos) << unknown;
  const std::string bad =
      ErrorOf(WriteScenario("pbad", "{log: run.mcap, perturb: {range: {noise_m: -1}}}"));
  EXPECT_NE(bad.find("s.yaml:2:"), std::string::npos) << bad;
  EXPECT_NE(bad.find("source.perturb.range.noise_m = -1; must be in [0, 100]"), std::string::npos)
      << bad;
}

// A path in a scenario's robot_overrides is relative to the scenario file, and errors about it
// name the scenario's line, not the robot file's.
TEST(ScenarioSpecTest, RobotOverridePathsAreRelativeToTheScenario) {
  const std::string dir = (std::filesystem::path(testing::TempDir()) / "spec_override_path")
                              .lexically_normal()
                              .string();
  std::filesystem::create_directories(dir + "/tex");
  const auto write = [&](const std::string& texture_dir) {
    const std::string path = dir + "/s.yaml";
    std::ofstream(path) << "name: cam\nworld: office\nrobot: ece276a\n"
                        << "robot_overrides: {camera.texture_dir: " << texture_dir << "}\n"
                        << "slam:\n  dr: {algorithm: dead-reckoning}\n";
    return path;
  };
  const ScenarioSpec spec = LoadScenario(write("tex"));
  ASSERT_TRUE(spec.simulated && spec.simulated->options.robot.camera);
  EXPECT_EQ(spec.simulated->options.robot.camera->texture_dir, dir + "/tex");
  const std::string missing = ErrorOf(write("nope"));
  EXPECT_NE(missing.find("s.yaml:4:"), std::string::npos) << missing;
  EXPECT_NE(missing.find("no such folder '" + dir + "/nope'"), std::string::npos) << missing;
}

}  // namespace
}  // namespace slamrig::scenario
