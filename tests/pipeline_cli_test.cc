// `slamrig slam` is a one-log scenario: it writes the metrics.json of `slamrig run` on the same
// log, a report that shows only what applies, and says when a log's times were made up.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

using testing::RunCommand;

const std::string kBinary = SLAMRIG_BINARY;

// Every key path of a JSON document ("configs.graph.run.map.width"), an expectation's name
// (a value of the run, not of the schema) aside.
void KeyPaths(const YAML::Node& node, const std::string& prefix, std::set<std::string>* out) {
  if (!node.IsMap()) return;
  for (const auto& kv : node) {
    const std::string path = prefix + kv.first.as<std::string>();
    out->insert(path);
    if (path != "expectations") KeyPaths(kv.second, path + ".", out);
  }
}

std::set<std::string> KeysOf(const std::string& metrics_json) {
  std::set<std::string> keys;
  KeyPaths(YAML::LoadFile(metrics_json), "", &keys);
  return keys;
}

// A short simulated office run as a CARMEN log: DIR/sim/run.log.
std::string SimulatedLog(const testing::TempDir& dir) {
  const auto r =
      RunCommand(kBinary + " simulate office --duration 6 --seed 2 --out " + dir.File("sim"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return dir.File("sim") + "/run.log";
}

TEST(PipelineCliTest, SlamAndALogScenarioWriteTheSameMetricsSchema) {
  testing::TempDir dir;
  const std::string log = SimulatedLog(dir);
  const auto slam =
      RunCommand(kBinary + " slam " + log + " --algorithm graph --quiet --out " + dir.File("slam"));
  ASSERT_EQ(slam.exit_code, 0) << slam.output;
  // A statistic the graph estimator reports is an expectation too.
  const std::string scenario = dir.File("log.yaml");
  std::ofstream(scenario) << "name: log\nsource: {log: " << log
                          << "}\nslam:\n  graph: {algorithm: graph}\n"
                             "  dead_reckoning: {algorithm: dead-reckoning}\n"
                             "expect:\n  graph: {inconsistent_max: 0, keyframes_min: 1}\n";
  const auto run = RunCommand(kBinary + " run " + scenario + " --quiet --out " + dir.File("run"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::set<std::string> slam_keys = KeysOf(dir.File("slam") + "/metrics.json");
  EXPECT_EQ(slam_keys, KeysOf(dir.File("run") + "/metrics.json"));
  EXPECT_TRUE(slam_keys.count("configs.graph.ate_rmse_m"));
  EXPECT_TRUE(slam_keys.count("configs.graph.inconsistent"));
  EXPECT_TRUE(slam_keys.count("configs.dead_reckoning.run.wall_time_s"));
  const YAML::Node metrics = YAML::LoadFile(dir.File("run") + "/metrics.json");
  EXPECT_EQ(metrics["expectations"]["graph.inconsistent_max"]["value"].as<double>(),
            metrics["configs"]["graph"]["inconsistent"].as<double>());
  // The files `slamrig slam` has always written are there beside the report.
  for (const char* f : {"trajectory.tum", "reference.tum", "map.pgm", "map.yaml", "report.html",
                        "config.yaml", "graph.tum"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.File("slam") + "/" + f)) << f;
  }
  // The report's config.yaml repeats the run.
  const auto again = RunCommand(kBinary + " run " + dir.File("slam") +
                                "/config.yaml --quiet --out " + dir.File("again"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(ReadFile(dir.File("slam") + "/graph.tum"), ReadFile(dir.File("again") + "/graph.tum"));
}

// The metric rows of a report.html: the text of each row's first cell in the metrics table.
std::vector<std::string> MetricRows(const std::string& html) {
  std::vector<std::string> rows;
  const std::size_t table = html.find("<h2>Metrics</h2>");
  const std::size_t end = html.find("</table>", table);
  for (std::size_t at = html.find("<tr><td>", table); at < end;
       at = html.find("<tr><td>", at + 1)) {
    const std::size_t from = at + 8;
    rows.push_back(html.substr(from, html.find("</td>", from) - from));
  }
  return rows;
}

TEST(PipelineCliTest, TheReportListsOnlyWhatApplies) {
  testing::TempDir dir;
  const std::string log = SimulatedLog(dir);
  const auto r = RunCommand(kBinary + " slam " + log +
                            " --algorithm dead-reckoning --quiet --out " + dir.File("dr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string html = ReadFile(dir.File("dr") + "/report.html");
  const std::vector<std::string> rows = MetricRows(html);
  ASSERT_FALSE(rows.empty()) << html;
  for (const std::string& row : rows) {
    EXPECT_EQ(row.rfind("texture_", 0), std::string::npos) << row;  // no camera
    EXPECT_EQ(row.rfind("loop_", 0), std::string::npos) << row;     // closes no loops
    EXPECT_NE(row, "false_loop_closures");
  }
  EXPECT_NE(std::find(rows.begin(), rows.end(), "ate_rmse_m"), rows.end());
  // n/a only where a metric applies but the run is too short for it (RPE over 10 m in 6 s).
  for (std::size_t at = html.find("n/a"); at != std::string::npos; at = html.find("n/a", at + 1)) {
    const std::size_t row = html.rfind("<tr><td>", at);
    EXPECT_EQ(html.compare(row + 8, 4, "rpe_"), 0) << html.substr(row, at - row);
  }
  EXPECT_EQ(html.find("<h2>Expectations</h2>"), std::string::npos);  // none given
  EXPECT_EQ(html.find("<h2>Floor texture</h2>"), std::string::npos);
  // And metrics.json holds no metric the configuration does not have.
  const YAML::Node dr =
      YAML::LoadFile(dir.File("dr") + "/metrics.json")["configs"]["dead-reckoning"];
  ASSERT_TRUE(dr.IsMap());
  EXPECT_FALSE(dr["loop_precision"]);
  EXPECT_FALSE(dr["texture_psnr_db"]);
  EXPECT_TRUE(dr["ate_rmse_m"]);
}

// The log's stamps zeroed: the reader makes times up from line order, and no real-time factor is
// claimed on the console, in metrics.json or in the report.
TEST(PipelineCliTest, SynthesisedTimesGiveNoRealTimeFactor) {
  testing::TempDir dir;
  std::istringstream in(ReadFile(SimulatedLog(dir)));
  std::ofstream zeroed(dir.File("zero.log"));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> tokens;
    std::istringstream words(line);
    for (std::string w; words >> w;) tokens.push_back(w);
    // Messages end in "timestamp hostname logger_timestamp".
    if (tokens.size() > 4 && tokens[0] != "PARAM" && tokens[0][0] != '#') {
      tokens[tokens.size() - 3] = "0";
      tokens.back() = "0";
    }
    for (std::size_t i = 0; i < tokens.size(); ++i) zeroed << (i ? " " : "") << tokens[i];
    zeroed << '\n';
  }
  zeroed.close();
  const auto r = RunCommand(kBinary + " slam " + dir.File("zero.log") +
                            " --algorithm dead-reckoning --quiet --out " + dir.File("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string said = "times synthesised from line order; no real-time factor";
  EXPECT_NE(r.output.find(said), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("real time)"), std::string::npos) << r.output;
  const std::string json = ReadFile(dir.File("out") + "/metrics.json");
  EXPECT_NE(json.find("\"times_synthesised\": true"), std::string::npos) << json;
  EXPECT_EQ(json.find("realtime_factor"), std::string::npos) << json;
  const std::string html = ReadFile(dir.File("out") + "/report.html");
  EXPECT_NE(html.find(said), std::string::npos);
  EXPECT_EQ(html.find("realtime_factor"), std::string::npos);
  // The untouched log has its real-time factor.
  const auto real =
      RunCommand(kBinary + " slam " + dir.File("sim") +
                 "/run.log --algorithm dead-reckoning --quiet --out " + dir.File("real"));
  ASSERT_EQ(real.exit_code, 0) << real.output;
  EXPECT_NE(real.output.find("x real time)"), std::string::npos) << real.output;
  EXPECT_NE(ReadFile(dir.File("real") + "/metrics.json").find("\"times_synthesised\": false"),
            std::string::npos);
}

}  // namespace
}  // namespace slamrig
