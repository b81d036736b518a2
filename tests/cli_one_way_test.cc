// The commands say things one way: `simulate --quiet` as `run --quiet`, one default robot for
// `simulate` and for a scenario that names none, and progress that never shares a line with
// the verdict when stderr is no terminal (here a pipe, as in a log file or CI).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

using ::testing::HasSubstr;
using ::testing::Not;
using testing::RunCommand;
using testing::TempDir;

std::string Slamrig(const std::string& args) { return std::string(SLAMRIG_BINARY) + " " + args; }

// The robot section of a report's config.yaml: from "robot:" to the next top-level key.
std::string RobotSection(const std::string& config_yaml) {
  std::istringstream lines(config_yaml);
  std::string out;
  bool inside = false;
  for (std::string line; std::getline(lines, line);) {
    const bool top_level = !line.empty() && line[0] != ' ' && line[0] != '#';
    if (top_level) inside = line.rfind("robot:", 0) == 0;
    if (inside) out += line + "\n";
  }
  return out;
}

TEST(CliOneWayTest, SimulateQuietPrintsNothingAndWritesTheSameRun) {
  TempDir dir;
  const auto loud = RunCommand(Slamrig("simulate office --duration 3 --out " + dir.File("a")));
  ASSERT_EQ(loud.exit_code, 0) << loud.output;
  EXPECT_THAT(loud.output, HasSubstr("office with ece276a, seed 1"));
  const auto quiet =
      RunCommand(Slamrig("simulate office --duration 3 --quiet --out " + dir.File("b")));
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
  EXPECT_GT(ReadFile(dir.File("a/run.log")).size(), 1000u);
  EXPECT_EQ(ReadFile(dir.File("a/run.log")), ReadFile(dir.File("b/run.log")));
  // Errors still come through.
  const auto bad =
      RunCommand(Slamrig("simulate office --quiet --format nope --out " + dir.File("c")));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.output, HasSubstr("--format: expected carmen"));
}

TEST(CliOneWayTest, AScenarioWithoutRobotDrivesSimulatesDefaultRobot) {
  TempDir dir;
  const std::string body =
      "name: no_robot\ndescription: d\nworld: office\nseed: 1\nduration_s: 2\n"
      "slam:\n  dead_reckoning:\n    algorithm: dead-reckoning\n";
  const std::string without = dir.Write("without.yaml", body);
  const auto run = RunCommand(Slamrig("run " + without + " --quiet --out " + dir.File("a")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // The robot `simulate` drives without --robot, resolved field by field as a scenario that
  // names it.
  const auto sim =
      RunCommand(Slamrig("simulate office --duration 2 --quiet --out " + dir.File("s")));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string named =
      dir.Write("named.yaml", body + "robot: " + dir.File("s/robot.yaml") + "\n");
  const auto run_named = RunCommand(Slamrig("run " + named + " --quiet --out " + dir.File("b")));
  ASSERT_EQ(run_named.exit_code, 0) << run_named.output;
  const std::string robot = RobotSection(ReadFile(dir.File("a/config.yaml")));
  EXPECT_THAT(robot, HasSubstr("name: ece276a"));
  EXPECT_GT(robot.size(), 200u);
  EXPECT_EQ(robot, RobotSection(ReadFile(dir.File("b/config.yaml"))));
  EXPECT_EQ(ReadFile(dir.File("a/truth.tum")), ReadFile(dir.File("b/truth.tum")));
}

// Every line whole: no carriage return, and the verdict line starts a line of its own.
void ExpectWholeLines(const std::string& output, const std::string& verdict) {
  EXPECT_THAT(output, Not(HasSubstr("\r")));
  const std::size_t at = output.find(verdict);
  ASSERT_NE(at, std::string::npos) << output;
  EXPECT_TRUE(at == 0 || output[at - 1] == '\n') << output;
}

TEST(CliOneWayTest, WithoutATerminalProgressNeverRunsIntoTheVerdict) {
  TempDir dir;
  const auto run = RunCommand(Slamrig(
      "run office_loop --set duration_s=3 --set slam.pf.particles=10 --out " + dir.File("r")));
  ASSERT_TRUE(run.exit_code == 0 || run.exit_code == 3) << run.output;
  ExpectWholeLines(run.output, "office_loop: ");

  const std::string sweep =
      dir.Write("sweep.yaml", std::string("scenario: ") + SLAMRIG_SOURCE_DIR +
                                  "/scenarios/office_loop.yaml\nseeds: 2\nparameters:\n"
                                  "  duration_s: [2]\n  slam.pf.particles: [5]\n"
                                  "metrics: [pf.ate_rmse_m]\n");
  const auto swept = RunCommand(Slamrig("sweep " + sweep + " --jobs 2 --out " + dir.File("w")));
  ASSERT_TRUE(swept.exit_code == 0 || swept.exit_code == 3) << swept.output;
  ExpectWholeLines(swept.output, sweep + ": 2 runs");
  EXPECT_THAT(swept.output, HasSubstr("2/2 runs"));  // progress, one line per finished run
}

}  // namespace
}  // namespace slamrig
