#include "slam/pipeline/external_estimator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "slam/pipeline/estimator_config.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

const ExternalEstimatorOptions& OptionsOf(const EstimatorConfig& config) {
  return dynamic_cast<const ExternalAlgorithmOptions&>(*config.options).options();
}

// The message of the ConfigError that reading `text` as configuration `mine` of s.yaml throws.
std::string Error(const std::string& text) {
  try {
    const YamlNode node = YamlNode::LoadString(text, "s.yaml");
    ParseEstimatorConfig("mine", node);
    node.CheckAllKeysUsed();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ExternalEstimatorTest, ReadsWritesAndRereadsItsOptions) {
  const YamlNode node = YamlNode::LoadString(
      "algorithm: external\ncommand: [python3, ./my slam.py, \"{input}\", \"--out={output}\", "
      "7, /bin/x]\ninput: mcap\ntimeout_s: 2.5\n",
      "s.yaml");
  const EstimatorConfig config = ParseEstimatorConfig("mine", node);
  node.CheckAllKeysUsed();
  const ExternalEstimatorOptions& o = OptionsOf(config);
  // ./ is relative to the scenario file (here none: the current folder), made absolute.
  const std::string script =
      (std::filesystem::current_path() / "my slam.py").lexically_normal().string();
  EXPECT_THAT(o.command, ::testing::ElementsAre("python3", script, "{input}", "--out={output}", "7",
                                                "/bin/x"));
  EXPECT_EQ(o.input, ExternalInput::kMcap);
  EXPECT_EQ(o.timeout_s, 2.5);

  YAML::Emitter out;
  WriteEstimatorConfig(config, &out);
  const YamlNode again = YamlNode::LoadString(out.c_str(), "again.yaml");
  const EstimatorConfig reread = ParseEstimatorConfig("mine", again);
  again.CheckAllKeysUsed();
  EXPECT_EQ(OptionsOf(reread).command, o.command);
  EXPECT_EQ(OptionsOf(reread).input, ExternalInput::kMcap);
  YAML::Emitter out2;
  WriteEstimatorConfig(reread, &out2);
  EXPECT_EQ(std::string(out.c_str()), std::string(out2.c_str()));
  JsonWriter json;
  WriteEstimatorConfigJson(config, &json);
  EXPECT_THAT(json.Finish(), ::testing::HasSubstr("\"--out={output}\""));
}

TEST(ExternalEstimatorTest, BadOptionsAreOneLineNamingFileLineAndKey) {
  EXPECT_THAT(Error("algorithm: external\n"),
              ::testing::AllOf(::testing::HasSubstr("s.yaml:1"),
                               ::testing::HasSubstr("command: required")));
  EXPECT_THAT(Error("algorithm: external\ncommand: []\n"),
              ::testing::HasSubstr("command: required"));
  EXPECT_THAT(Error("algorithm: external\ncommand: ./x.py\n"),
              ::testing::HasSubstr("s.yaml:2:10: command: expected a list of texts"));
  // An unquoted {input} is a YAML map, not a text.
  EXPECT_THAT(Error("algorithm: external\ncommand: [x, {input}]\n"),
              ::testing::HasSubstr("s.yaml:2:14: command[1]: expected a text"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\ninput: rosbag\n"),
              ::testing::HasSubstr("s.yaml:3:8: input: 'rosbag' is not one of: carmen, mcap, "
                                   "sqlite3, ece276a"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\ntimeout_s: 0\n"),
              ::testing::HasSubstr("timeout_s = 0; must be > 0"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\ntimeout_s: -3\n"),
              ::testing::HasSubstr("timeout_s = -3; must be > 0"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\ntimeout: 3\n"),
              ::testing::HasSubstr("timeout"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [\"\", a]\n"),
              ::testing::HasSubstr("command[0]: the program is an empty text"));
  EXPECT_EQ(Error("algorithm: external\ncommand: [x]\n"), "no error");
}

TEST(ExternalEstimatorTest, StreamOptionsAreReadAndChecked) {
  const YamlNode node = YamlNode::LoadString(
      "algorithm: external\ncommand: [x, \"--seed={seed}\"]\nmode: stream\nanswer_timeout_s: 2\n",
      "s.yaml");
  // The config owns the options: kept alive for as long as `o` is read.
  const EstimatorConfig config = ParseEstimatorConfig("mine", node);
  const ExternalEstimatorOptions& o = OptionsOf(config);
  EXPECT_EQ(o.mode, ExternalMode::kStream);
  EXPECT_EQ(o.answer_timeout_s, 2.0);
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\nmode: online\n"),
              ::testing::HasSubstr("s.yaml:3:7: mode: 'online' is not one of: offline, stream"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\nmode: stream\nanswer_timeout_s: 0\n"),
              ::testing::HasSubstr("answer_timeout_s = 0; must be > 0"));
  EXPECT_THAT(Error("algorithm: external\ncommand: [x, \"{input}\"]\nmode: stream\n"),
              ::testing::HasSubstr("command[1] = '{input}'; {input} has no meaning with mode "
                                   "stream (the records come on stdin, the poses go to stdout)"));
  EXPECT_EQ(Error("algorithm: external\ncommand: [x, \"{input}\"]\n"), "no error");
  EXPECT_THAT(Error("algorithm: external\ncommand: [x]\nmode: stream\ninput: mcap\n"),
              ::testing::HasSubstr("input: set with mode stream, which always streams MCAP"));
}

// Logs what a stream is given, in order, and answers each scan with (its time, 0, 0).
class LoggingLink final : public ExternalStreamLink {
 public:
  explicit LoggingLink(std::vector<std::string>* log) : log_(log) {}
  void Record(const slamrig::Record& record) override {
    log_->push_back(std::string(std::holds_alternative<OdometryPose>(record) ? "odom " : "ticks ") +
                    std::to_string(RecordTime(record).ns));
  }
  std::optional<Pose2> Scan(const LaserScan& scan) override {
    log_->push_back("scan " + std::to_string(scan.time.ns));
    return Pose2(scan.time.seconds(), 0.0, 0.0);
  }
  void Finish() override { log_->push_back("finish"); }
  std::string failure() const override { return ""; }
  const std::optional<OccupancyGrid>& map() const override { return map_; }
  std::map<std::string, double> Statistics() const override { return {{"child_wall_s", 1.0}}; }

 private:
  std::vector<std::string>* log_;
  std::optional<OccupancyGrid> map_;
};

// A scan reaches the program when the estimators take it: with odometry poses after the next
// pose (its odometry is interpolated from both sides); with wheel ticks at once.
TEST(ExternalEstimatorTest, StreamGetsEachScanAfterTheOdometryItWaitsFor) {
  const YamlNode node =
      YamlNode::LoadString("algorithm: external\ncommand: [x]\nmode: stream\n", "s.yaml");
  const EstimatorConfig config = ParseEstimatorConfig("mine", node);
  const auto scan = [](std::int64_t ns) {
    LaserScan s;
    s.time = Time{ns};
    s.ranges_m = {1.0f};
    return Record{s};
  };
  const auto odom = [](std::int64_t ns) { return Record{OdometryPose{Time{ns}, Pose2()}}; };
  WheelTicks ticks;
  ticks.right_ticks = ticks.left_ticks = {1};
  const auto tick = [&](std::int64_t ns) {
    ticks.time = Time{ns};
    return Record{ticks};
  };
  const std::vector<std::pair<OdometrySource, std::vector<Record>>> cases = {
      {OdometrySource::kOdometryPoses, {odom(0), scan(10), scan(20), odom(30), scan(40)}},
      {OdometrySource::kWheelTicks, {tick(0), scan(10), scan(20), tick(30), scan(40)}}};
  const std::vector<std::vector<std::string>> expected = {
      {"odom 0", "odom 30", "scan 10", "scan 20", "scan 40", "finish"},
      {"ticks 0", "scan 10", "scan 20", "ticks 30", "scan 40", "finish"}};
  for (std::size_t c = 0; c < cases.size(); ++c) {
    EstimatorRunner runner(config, cases[c].first, 1);
    std::vector<std::string> log;
    dynamic_cast<ExternalEstimator&>(runner.estimator())
        .Attach(std::make_unique<LoggingLink>(&log));
    for (const Record& r : cases[c].second) runner.Add(r);
    runner.Finish();
    EXPECT_EQ(log, expected[c]);
    const EstimatorRun run = runner.TakeResult();
    ASSERT_EQ(run.online.size(), 3u);
    EXPECT_EQ(run.online.poses()[2].pose.x(), Time{40}.seconds());
    EXPECT_EQ(run.statistics.at("child_wall_s"), 1.0);
  }
}

// A caller that starts no program (the Python module's run_estimator) gets an error, not a crash.
TEST(ExternalEstimatorTest, StreamWithoutItsProgramIsAnError) {
  const YamlNode node =
      YamlNode::LoadString("algorithm: external\ncommand: [x]\nmode: stream\n", "s.yaml");
  EstimatorRunner runner(ParseEstimatorConfig("mine", node), OdometrySource::kNone, 1);
  LaserScan scan;
  scan.ranges_m = {1.0f};
  try {
    runner.Add(scan);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("mode stream runs its program from the scenario "
                                               "runner"));
  }
}

TEST(ExternalEstimatorTest, SubstitutesEveryPlaceholderOnceAndNothingElse) {
  const std::vector<std::string> command = {
      "prog",    "{input}", "--out={output}", "{seed}{seed}", "{inputs}",
      "{Input}", "{",       "plain",          "x{input}y"};
  EXPECT_THAT(SubstituteExternalArguments(command, "/d/in.log", "/d/out.tum", 42),
              ::testing::ElementsAre("prog", "/d/in.log", "--out=/d/out.tum", "4242", "{inputs}",
                                     "{Input}", "{", "plain", "x/d/in.logy"));
  // A value holding a placeholder is not replaced again.
  EXPECT_THAT(SubstituteExternalArguments({"{input}", "{output}"}, "{output}", "{seed}",
                                          18446744073709551615ull),
              ::testing::ElementsAre("{output}", "{seed}"));
  EXPECT_THAT(SubstituteExternalArguments({"a{seed}b"}, "", "", 0), ::testing::ElementsAre("a0b"));
}

}  // namespace
}  // namespace slamrig::slam
