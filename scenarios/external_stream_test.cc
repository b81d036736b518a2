// External programs in `mode: stream` in a short simulated office run (integration: a
// simulation and a dozen programs, ~10 s): the shipped Python and C++ clients give the built-in
// dead reckoning's bits, and each broken program fails alone with its line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "tests/util/read_file.h"

namespace slamrig::scenario {
namespace {

using slamrig::testing::ReadFile;

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

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

// A Python program that runs the shipped client with `patch` applied to it first.
std::string Patched(const std::string& patch) {
  return "import struct, sys, time\nsys.path.insert(0, '" + std::string(SLAMRIG_SOURCE_DIR) +
         "/examples/external')\nimport stream_dead_reckoning as c\npose, close = c.Writer.pose, "
         "c.Writer.close\n" +
         patch + "\nc.main()\n";
}

void WritePrograms(const fs::path& dir) {
  std::ofstream(dir / "crash.py") << "import os, sys\nsys.stdin.buffer.read(64)\n"
                                     "print('lost in the corridor', file=sys.stderr)\n"
                                     "sys.stderr.flush()\nos.abort()\n";
  std::ofstream(dir / "quits.py") << "import sys\nsys.exit(3)\n";  // reads nothing: EPIPE
  std::ofstream(dir / "garbage.py")
      << "import sys\nsys.stdout.write('no poses here\\n')\nsys.stdout.flush()\n"
         "sys.stdin.buffer.read()\n";
  // Stops after 100 poses, exits 0.
  std::ofstream(dir / "too_few.py") << Patched(
      "def p(self, *a):\n    if self.seq == 100: sys.exit(0)\n    pose(self, *a)\n"
      "c.Writer.pose = p");
  // One pose more after the last scan.
  std::ofstream(dir / "too_many.py") << Patched(
      "def e(self):\n    pose(self, 1, 0.0, 0.0, 0.0)\n    close(self)\nc.Writer.close = e");
  // Every pose twice.
  std::ofstream(dir / "doubled.py")
      << Patched("def p(self, *a):\n    pose(self, *a)\n    pose(self, *a)\nc.Writer.pose = p");
  // 5 ms per scan: past timeout_s = 1 s.
  std::ofstream(dir / "slow.py") << Patched(
      "def p(self, *a):\n    time.sleep(0.005)\n    pose(self, *a)\nc.Writer.pose = p");
  // A 20 x 20 map at the end, 0.1 m cells from (-1, -1): free but its last row.
  std::ofstream(dir / "mapped.py") << Patched(
      "def e(self):\n"
      "    self.record(3, struct.pack('<H', 2) + self.s(b'nav_msgs/msg/OccupancyGrid') + "
      "self.s(b'ros2msg') + self.s(b''))\n"
      "    self.record(4, struct.pack('<HH', 1, 2) + self.s(b'/map') + self.s(b'cdr') + "
      "struct.pack('<I', 0))\n"
      "    cdr = (b'\\0\\1\\0\\0' + struct.pack('<iII', 0, 0, 4) + b'map\\0' + "
      "struct.pack('<iIfII', 0, 0, 0.1, 20, 20) + bytes(4) + struct.pack('<7d', -1, -1, 0, 0, 0, "
      "0, 1) + struct.pack('<I', 400) + bytes([0] * 380 + [100] * 20))\n"
      "    self.record(5, struct.pack('<HIQQ', 1, 0, 0, 0) + cdr)\n"
      "    close(self)\n"
      "c.Writer.close = e");
}

// 20 s of the office: the built-in dead reckoning, the two shipped stream clients, and broken
// programs beside them.
TEST(ExternalStreamTest, ClientsGiveTheBuiltInsBitsAndBrokenProgramsFailAlone) {
  const fs::path dir = fs::temp_directory_path() / "slamrig_external_stream_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  WritePrograms(dir);
  const std::string source = SLAMRIG_SOURCE_DIR;
  const auto python = [&](const std::string& name,
                          const std::string& timeouts = "timeout_s: 60, answer_timeout_s: 10") {
    return "  " + name + ": {algorithm: external, mode: stream, command: [python3, " +
           (dir / (name + ".py")).string() + "], " + timeouts + "}\n";
  };
  std::ofstream(dir / "s.yaml")
      << "name: external_stream_test\nworld: " << source << "/worlds/office.yaml\nrobot: " << source
      << "/robots/ece276a.yaml\nseed: 3\nduration_s: 20\nslam:\n"
      << "  dead_reckoning: {algorithm: dead-reckoning}\n"
      << "  stream_py: {algorithm: external, mode: stream, command: [python3, " << source
      << "/examples/external/stream_dead_reckoning.py]}\n"
      << "  stream_cc: {algorithm: external, mode: stream, command: [" << SLAMRIG_STREAM_CLIENT
      << "]}\n"
      << python("crash") << python("quits") << python("garbage") << python("too_few")
      << python("too_many") << python("doubled") << python("slow", "timeout_s: 1")
      << python("mapped")
      << "  hang: {algorithm: external, mode: stream, command: [sleep, \"60\"], "
         "answer_timeout_s: 1}\n"
      << "expect:\n  dead_reckoning: {ate_rmse_m_max: 1.0}\n  stream_cc: {ate_rmse_m_max: 1.0}\n";
  const ScenarioSpec spec = LoadScenario((dir / "s.yaml").string());
  RunnerOptions options;
  options.work_dir = (dir / "report").string();
  const ScenarioResult r = RunScenario(spec, options);

  const ConfigResult* builtin = Find(r, "dead_reckoning");
  ASSERT_TRUE(builtin);
  ASSERT_GT(builtin->online.size(), 700u);  // 40 Hz for 20 s
  for (const char* name : {"stream_py", "stream_cc"}) {
    const ConfigResult* client = Find(r, name);
    ASSERT_TRUE(client) << Failure(r, name);
    ASSERT_EQ(client->online.size(), builtin->online.size()) << name;
    // The same arithmetic on the same bits: positions equal, and each yaw the one whose
    // quaternion (what /estimate carries) is the built-in's.
    for (std::size_t i = 0; i < builtin->online.size(); ++i) {
      const StampedPose& a = builtin->run.online.poses()[i];
      const StampedPose& b = client->run.online.poses()[i];
      ASSERT_EQ(a.time, b.time) << name << " " << i;
      ASSERT_EQ(a.pose.x(), b.pose.x()) << name << " " << i;
      ASSERT_EQ(a.pose.y(), b.pose.y()) << name << " " << i;
      ASSERT_EQ(std::sin(0.5 * a.pose.theta()), std::sin(0.5 * b.pose.theta())) << name << i;
      ASSERT_EQ(std::cos(0.5 * a.pose.theta()), std::cos(0.5 * b.pose.theta())) << name << i;
    }
    for (const char* metric : {"ate_rmse_m", "ate_max_m", "final_error_m", "rpe_m_per_1m"})
      EXPECT_EQ(client->metrics.at(metric), builtin->metrics.at(metric)) << name << metric;
    EXPECT_EQ(client->metrics.count("map_f1"), 0u);
    EXPECT_GT(client->metrics.at("peak_rss_mib"), 1.0) << name;
    EXPECT_GT(client->metrics.at("child_wall_s"), 0.0) << name;
    EXPECT_GT(client->metrics.at("input_write_s"), 0.0) << name;
  }
  const ConfigResult* mapped = Find(r, "mapped");
  ASSERT_TRUE(mapped) << Failure(r, "mapped");
  EXPECT_EQ(mapped->run.map.width(), 20);
  EXPECT_EQ(mapped->metrics.count("map_f1"), 1u);
  EXPECT_EQ(mapped->metrics.at("ate_rmse_m"), builtin->metrics.at("ate_rmse_m"));

  const std::string scans = std::to_string(builtin->online.size());
  EXPECT_EQ(r.failures.size(), 8u);
  EXPECT_THAT(Failure(r, "crash"),
              AllOf(HasSubstr("python3: killed by signal 6 (Aborted) before answering scan 1 "
                              "(wrote 0 poses for 1 scans); stderr: lost in the corridor")));
  EXPECT_THAT(Failure(r, "quits"),
              HasSubstr("python3: exit code 3 before answering scan 1 (wrote 0 poses for 1 "
                        "scans)"));
  EXPECT_THAT(Failure(r, "garbage"),
              HasSubstr("python3: its stdout: byte 0: not an MCAP stream (it starts with 'no "
                        "poses here\\x0a')"));
  EXPECT_THAT(Failure(r, "too_few"),
              HasSubstr("python3: exited before answering scan 101 (wrote 100 poses for 101 "
                        "scans)"));
  EXPECT_THAT(Failure(r, "too_many"),
              HasSubstr("python3: wrote " + std::to_string(builtin->online.size() + 1) +
                        " poses for " + scans + " scans (one pose per scan, at its stamp)"));
  EXPECT_THAT(Failure(r, "doubled"),
              AllOf(HasSubstr("python3: pose 2 is stamped"), HasSubstr(", scan 2 at"),
                    HasSubstr("one pose per scan, in scan order, with the scan's stamp")));
  EXPECT_THAT(Failure(r, "slow"), HasSubstr("python3: still running after timeout_s = 1 s; "
                                            "killed (wrote "));
  EXPECT_THAT(Failure(r, "hang"),
              AllOf(HasSubstr("sleep: no pose for scan 1 ("),
                    HasSubstr(") within answer_timeout_s = 1 s; killed (wrote 0 poses for 1 "
                              "scans)")));
  // The run fails for the broken ones only: the others' expectations hold.
  EXPECT_FALSE(r.passed);
  for (const ExpectationOutcome& o : r.outcomes) EXPECT_TRUE(o.passed) << o.Describe();

  // The trajectories the report writes are the built-in's, byte for byte.
  WriteReport(r, options.work_dir);
  const std::string builtin_tum = ReadFile(dir / "report/dead_reckoning.tum");
  EXPECT_GT(builtin_tum.size(), 10000u);
  EXPECT_EQ(ReadFile(dir / "report/stream_py.tum"), builtin_tum);
  EXPECT_EQ(ReadFile(dir / "report/stream_cc.tum"), builtin_tum);
  EXPECT_THAT(ReadFile(dir / "report/metrics.json"),
              HasSubstr("\"failure\": \"python3: killed by signal 6"));
  EXPECT_THAT(ReadFile(dir / "report/crash_stderr.txt"), HasSubstr("lost in the corridor"));
  fs::remove_all(dir);
}

// A log with odometry poses only (intel): each /scan comes after the /odom past it, and both
// clients interpolate the poses to it; they agree with each other exactly and with the built-in
// (which interpolates at constant twist, they linearly) to a few parts per million.
TEST(ExternalStreamTest, OnALogTheClientsInterpolateItsOdometryPoses) {
  const fs::path log =
      fs::path(SLAMRIG_SOURCE_DIR) / "../shared/datasets/carmen_corrected/intel-corrected.log.gz";
  if (!fs::exists(log)) GTEST_SKIP() << log << " is not there";
  const fs::path dir = fs::temp_directory_path() / "slamrig_external_stream_log_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "s.yaml")
      << "name: intel_stream\nsource: {log: " << log.lexically_normal().string()
      << "}\nseed: 1\nslam:\n  dead_reckoning: {algorithm: dead-reckoning}\n"
      << "  stream_py: {algorithm: external, mode: stream, command: [python3, "
      << SLAMRIG_SOURCE_DIR << "/examples/external/stream_dead_reckoning.py]}\n"
      << "  stream_cc: {algorithm: external, mode: stream, command: [" << SLAMRIG_STREAM_CLIENT
      << "]}\n";
  const ScenarioSpec spec = LoadScenario((dir / "s.yaml").string());
  RunnerOptions options;
  options.work_dir = (dir / "report").string();
  const ScenarioResult r = RunScenario(spec, options);
  const ConfigResult* builtin = Find(r, "dead_reckoning");
  const ConfigResult* py = Find(r, "stream_py");
  const ConfigResult* cc = Find(r, "stream_cc");
  ASSERT_TRUE(builtin && py && cc) << Failure(r, "stream_py") << Failure(r, "stream_cc");
  ASSERT_EQ(py->online.size(), 910u);
  ASSERT_EQ(cc->online.size(), 910u);
  for (std::size_t i = 0; i < py->online.size(); ++i) {
    ASSERT_EQ(py->run.online.poses()[i].pose.x(), cc->run.online.poses()[i].pose.x()) << i;
    ASSERT_EQ(py->run.online.poses()[i].pose.y(), cc->run.online.poses()[i].pose.y()) << i;
  }
  const double ate = builtin->metrics.at("ate_rmse_m");
  EXPECT_GT(ate, 20.0);  // intel's raw odometry drifts
  EXPECT_NEAR(py->metrics.at("ate_rmse_m"), ate, 1e-5 * ate);
  EXPECT_EQ(cc->metrics.at("ate_rmse_m"), py->metrics.at("ate_rmse_m"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace slamrig::scenario
