// The scan matching of an external program's poses (unit), and external programs in a short
// simulated office run (integration: a simulation and five Python processes, ~10 s).
#include "scenarios/external_run.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "slam/io/log_reader.h"
#include "slam/pipeline/estimator_runner.h"
#include "slam/types/pose2.h"
#include "tests/util/read_file.h"

namespace slamrig::scenario {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;

Trajectory At(const std::vector<double>& seconds) {
  Trajectory t;
  for (double s : seconds) t.Append(Time::FromSeconds(s), Pose2(s, 0.0, 0.0));
  return t;
}

std::vector<Time> Times(const std::vector<double>& seconds) {
  std::vector<Time> times;
  for (double s : seconds) times.push_back(Time::FromSeconds(s));
  return times;
}

TEST(MatchPosesToScansTest, OnePosePerScanWithinTheTolerance) {
  std::string error;
  // 0.4 ms off at 40 Hz scans: within 1 ms. Stamped with the scans' own times.
  const auto matched =
      MatchPosesToScans(At({0.0004, 0.025, 0.0496}), Times({0.0, 0.025, 0.05}), &error);
  ASSERT_TRUE(matched) << error;
  EXPECT_EQ(matched->poses()[2].time, Time::FromSeconds(0.05));
  EXPECT_EQ(matched->poses()[2].pose.x(), 0.0496);
  // 2 ms off: no.
  EXPECT_FALSE(MatchPosesToScans(At({0.0, 0.027}), Times({0.0, 0.025}), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("pose 2 is stamped 0.027000000 s, scan 2 at 0.025"));
  // Scans 1 ms apart: the tolerance shrinks to half their gap.
  EXPECT_FALSE(MatchPosesToScans(At({0.0, 0.0016}), Times({0.0, 0.001}), &error));
  EXPECT_TRUE(MatchPosesToScans(At({0.0, 0.0014}), Times({0.0, 0.001}), &error));
  // Equal stamps (a log's) are matched in order; stamps going backwards too.
  EXPECT_TRUE(MatchPosesToScans(At({1.0, 1.0, 0.5}), Times({1.0, 1.0, 0.5}), &error));
}

TEST(MatchPosesToScansTest, NamesBothCountsWhenThereAreMoreOrFewerPoses) {
  std::string error;
  EXPECT_FALSE(MatchPosesToScans(At({0.0, 0.1}), Times({0.0, 0.1, 0.2}), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("wrote 2 poses for 3 scans"));
  EXPECT_FALSE(MatchPosesToScans(At({0.0, 0.1, 0.2, 0.3}), Times({0.0, 0.1, 0.2}), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("wrote 4 poses for 3 scans"));
  EXPECT_TRUE(MatchPosesToScans(At({}), Times({}), &error));
}

const ConfigResult* Find(const ScenarioResult& r, const std::string& name) {
  for (const ConfigResult& c : r.configs)
    if (c.name == name) return &c;
  return nullptr;
}

std::string Failure(const ScenarioResult& r, const std::string& name) {
  for (const ConfigFailure& f : r.failures)
    if (f.name == name) return f.message;
  return "not failed";
}

// 20 s of the office loop: the built-in dead reckoning, the shipped Python client on the run as
// a CARMEN log, and four broken programs beside them. Each broken one fails alone, named with
// what went wrong; the others are scored.
TEST(ExternalRunTest, ProgramsFailAloneAndTheClientMatchesBuiltInDeadReckoning) {
  const fs::path dir = fs::temp_directory_path() / "slamrig_external_run_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string source = SLAMRIG_SOURCE_DIR;
  const std::string client = source + "/examples/external/dead_reckoning.py";
  // Cuts the client's output short by 5 poses.
  const std::string too_few =
      "import subprocess, sys; subprocess.run([sys.executable, '" + client +
      "', sys.argv[1], sys.argv[2]], check=True); lines = open(sys.argv[2]).readlines(); "
      "open(sys.argv[2], 'w').writelines(lines[:-5])";
  // The client, then a 20 x 20 map_server map beside its output: all free but a wall row.
  const std::string mapped =
      "import subprocess, sys; subprocess.run([sys.executable, '" + client +
      "', sys.argv[1], sys.argv[2]], check=True); "
      "open('output.pgm', 'wb').write(b'P5 20 20 255 ' + bytes([254] * 380 + [0] * 20)); "
      "open('output.yaml', 'w').write('image: output.pgm\\\\nresolution: 0.1\\\\norigin: [-1, -1, "
      "0]\\\\nnegate: 0\\\\noccupied_thresh: 0.65\\\\nfree_thresh: 0.196\\\\n')";
  std::ofstream(dir / "s.yaml")
      << "name: external_test\nworld: " << source << "/worlds/office.yaml\nrobot: " << source
      << "/robots/ece276a.yaml\nseed: 3\nduration_s: 20\nslam:\n"
      << "  dead_reckoning: {algorithm: dead-reckoning}\n"
      << "  external_dr: {algorithm: external, command: [python3, " << client
      << ", \"{input}\", \"{output}\"], timeout_s: 60}\n"
      << "  crash: {algorithm: external, command: [python3, -c, \"import os, sys; "
         "print('lost in the corridor', file=sys.stderr); sys.stderr.flush(); os.abort()\"]}\n"
      << "  hang: {algorithm: external, command: [python3, -c, \"import time; "
         "time.sleep(60)\"], timeout_s: 1}\n"
      << "  garbage: {algorithm: external, command: [python3, -c, \"import sys; "
         "open(sys.argv[1], 'w').write('no trajectory here')\", \"{output}\"]}\n"
      << "  too_few: {algorithm: external, command: [python3, -c, \"" << too_few
      << "\", \"{input}\", \"{output}\"]}\n"
      << "  mapped: {algorithm: external, command: [python3, -c, \"" << mapped
      << "\", \"{input}\", \"{output}\"]}\n"
      << "  mcap: {algorithm: external, command: [\"true\"], input: mcap}\n"
      << "expect:\n  dead_reckoning: {ate_rmse_m_max: 1.0}\n  external_dr: {ate_rmse_m_max: 1.0}\n";
  const ScenarioSpec spec = LoadScenario((dir / "s.yaml").string());
  RunnerOptions options;
  options.work_dir = (dir / "report").string();
  const ScenarioResult r = RunScenario(spec, options);

  const ConfigResult* builtin = Find(r, "dead_reckoning");
  const ConfigResult* external = Find(r, "external_dr");
  ASSERT_TRUE(builtin && external);
  ASSERT_EQ(external->estimate.size(), builtin->estimate.size());
  ASSERT_GT(builtin->estimate.size(), 700u);  // 40 Hz for 20 s
  // Exactly: the built-in dead reckoning on the CARMEN log the program read gives its poses
  // (the writer prints every number as its shortest round-trip text, so nothing is lost).
  const slam::Dataset log = slam::ReadLog((dir / "report/external/external_dr/input.log").string());
  const slam::EstimatorRun replay =
      slam::RunEstimator(slam::DefaultEstimatorConfig("dr", "dead-reckoning"), log.records, 1);
  ASSERT_EQ(replay.final.size(), external->run.final.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < replay.final.size(); ++i) {
    const Pose2& a = replay.final.poses()[i].pose;
    const Pose2& b = external->run.final.poses()[i].pose;
    largest = std::max({largest, (a.translation() - b.translation()).norm(),
                        std::abs(NormalizeAngle(a.theta() - b.theta()))});
  }
  EXPECT_LT(largest, 1e-9);
  // Against the built-in on the records themselves: the log's ODOM lines are the robot's odometry
  // integrated between encoder readings and interpolated to each scan, where the built-in
  // integrates up to each scan's time; the two differ by millimetres over a run (a lap: ATE
  // 0.1552 against 0.1554 m, 10 mm apart at most; docs/external.md), far below the ATE.
  const double ate_builtin = builtin->metrics.at("ate_rmse_m");
  const double ate_external = external->metrics.at("ate_rmse_m");
  EXPECT_GT(ate_builtin, 0.005);
  EXPECT_NEAR(ate_external, ate_builtin, 0.01 * ate_builtin);
  EXPECT_NEAR(external->metrics.at("final_error_m"), builtin->metrics.at("final_error_m"), 0.005);
  // No map written, no map metrics; a map written is scored.
  EXPECT_EQ(external->metrics.count("map_f1"), 0u);
  const ConfigResult* with_map = Find(r, "mapped");
  ASSERT_TRUE(with_map) << Failure(r, "mapped");
  EXPECT_EQ(with_map->run.map.width(), 20);
  // Scored (its toy wall lies nowhere near the office's, so its F1 is what it is).
  EXPECT_EQ(with_map->metrics.count("map_f1"), 1u);
  EXPECT_EQ(with_map->metrics.count("map_precision"), 1u);
  EXPECT_GE(builtin->metrics.at("map_f1"), 0.0);
  EXPECT_GT(external->metrics.at("peak_rss_mib"), 1.0);
  EXPECT_GT(external->metrics.at("child_wall_s"), 0.0);

  EXPECT_EQ(r.failures.size(), 5u);
  EXPECT_THAT(Failure(r, "crash"), ::testing::AllOf(::testing::HasSubstr("killed by signal 6"),
                                                    ::testing::HasSubstr("lost in the corridor")));
  EXPECT_THAT(Failure(r, "hang"),
              ::testing::HasSubstr("still running after timeout_s = 1 s; killed"));
  EXPECT_THAT(Failure(r, "garbage"), ::testing::AllOf(::testing::HasSubstr("not a TUM trajectory"),
                                                      ::testing::HasSubstr("output.tum:1")));
  const std::string scans = std::to_string(builtin->estimate.size());
  EXPECT_THAT(Failure(r, "too_few"),
              ::testing::HasSubstr("wrote " + std::to_string(builtin->estimate.size() - 5) +
                                   " poses for " + scans + " scans"));
  EXPECT_THAT(Failure(r, "mcap"), ::testing::HasSubstr("exited with code 0 but wrote no"));
  // The mcap input holds the scans every configuration got.
  const slam::Dataset bag = slam::ReadLog((dir / "report/external/mcap/input").string());
  std::size_t bag_scans = 0;
  for (const Record& record : bag.records) bag_scans += std::holds_alternative<LaserScan>(record);
  EXPECT_EQ(bag_scans, builtin->estimate.size());

  // The run is a failure for the broken ones only: the others' expectations hold.
  EXPECT_FALSE(r.passed);
  for (const ExpectationOutcome& o : r.outcomes) EXPECT_TRUE(o.passed) << o.Describe();
  WriteReport(r, options.work_dir);
  const std::string metrics = ReadFile(dir / "report/metrics.json");
  EXPECT_THAT(metrics, ::testing::HasSubstr("\"failure\": \"python3: killed by signal 6"));
  EXPECT_THAT(ReadFile(dir / "report/crash_stderr.txt"),
              ::testing::HasSubstr("lost in the corridor"));
  EXPECT_THAT(ReadFile(dir / "report/external_dr_stdout.txt"),
              ::testing::HasSubstr("dead_reckoning.py: " + scans + " poses"));
  EXPECT_THAT(ExpectationTable(r), ::testing::HasSubstr("FAIL   hang (external) failed:"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace slamrig::scenario
