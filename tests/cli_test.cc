// The slamrig command line as a user meets it: help, a real run, and hostile input.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "tests/util/dataset.h"
#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

using ::testing::HasSubstr;
using testing::RunCommand;
using ::testing::StartsWith;
using testing::TempDir;

std::string Slamrig(const std::string& args) { return std::string(SLAMRIG_BINARY) + " " + args; }

// `text` without its comment lines and the lines holding one of `words`.
std::string Without(const std::string& text, const std::vector<std::string>& words) {
  std::istringstream lines(text);
  std::string out;
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line[0] == '#') continue;
    if (std::none_of(words.begin(), words.end(),
                     [&](const std::string& w) { return line.find(w) != std::string::npos; })) {
      out += line + "\n";
    }
  }
  return out;
}

int CountLines(const std::string& text) {
  int lines = 0;
  for (const char c : text) lines += c == '\n';
  return lines;
}

TEST(CliTest, HelpListsCommandsAndPerCommandHelp) {
  const auto help = RunCommand(Slamrig("--help"));
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_THAT(help.output, HasSubstr("map "));
  const auto map_help = RunCommand(Slamrig("map --help"));
  EXPECT_EQ(map_help.exit_code, 0);
  EXPECT_THAT(map_help.output, HasSubstr("Usage: slamrig map LOG --out DIR"));
  EXPECT_THAT(map_help.output, HasSubstr("--resolution M"));
  EXPECT_EQ(RunCommand(Slamrig("help map")).output, map_help.output);
  const auto unknown = RunCommand(Slamrig("mapp"));
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.output, HasSubstr("unknown command 'mapp'"));
}

TEST(CliTest, MapsASliceOfIntel) {
  SLAMRIG_REQUIRE_DATASET(intel, "carmen_corrected/intel-corrected.log.gz");
  TempDir dir;
  // The first 3,000 lines: about 150 scans.
  const std::string slice = dir.File("slice.log");
  ASSERT_EQ(std::system(("zcat " + intel + " | head -n 3000 > " + slice).c_str()), 0);
  const auto run = RunCommand(Slamrig("map " + slice + " --out " + dir.File("out")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("scans mapped"));
  for (const char* f : {"map.pgm", "map.yaml", "map.png", "trajectory.tum"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.File(std::string("out/") + f))) << f;
  }
}

// Each broken input: one error line naming the file (and line), non-zero exit, no output.
TEST(CliTest, BrokenCarmenInputFailsCleanly) {
  TempDir dir;
  const std::string good =
      "ODOM 0 0 0 0 0 0 1.0 h 1.0\n"
      "FLASER 3 1.0 1.5 2.0 0 0 0 0 0 0 1.1 h 1.1\n";
  struct Case {
    std::string name, contents, expected;
  };
  const std::vector<Case> cases = {
      {"truncated.log", good + "FLASER 3 1.0 1.5 2.0 0 0\n",
       "truncated.log:3: FLASER line: expected 14 fields"},
      {"nan.log", good + "FLASER 3 1.0 nan 2.0 0 0 0 0 0 0 1.2 h 1.2\n",
       "nan.log:3: FLASER range[1]: not a finite number"},
      {"beams.log", good + "FLASER 4 1.0 1.5 2.0 0 0 0 0 0 0 1.2 h 1.2\n",
       "beams.log:3: FLASER line: expected 15 fields"},
      {"empty.log", "", "empty.log: empty file"},
      {"garbage.log", std::string("\x89PNG\r\n\x1a\n\x01\x02\x03binary", 17),
       "garbage.log:1: line: binary data"},
  };
  for (const Case& c : cases) {
    const std::string out = dir.File("out_" + c.name);
    const auto run = RunCommand(Slamrig("map " + dir.Write(c.name, c.contents) + " --out " + out));
    EXPECT_NE(run.exit_code, 0) << c.name;
    EXPECT_EQ(CountLines(run.output), 1) << run.output;
    EXPECT_THAT(run.output, StartsWith("slamrig: error: "));
    EXPECT_THAT(run.output, HasSubstr(c.expected)) << c.name;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.name;
  }
  const auto missing =
      RunCommand(Slamrig("map " + dir.File("nope.log") + " --out " + dir.File("o")));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_THAT(missing.output, HasSubstr("nope.log: no such file"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("o")));
}

TEST(CliTest, BadFlagsFailWithUsageError) {
  TempDir dir;
  const std::string log = dir.Write("a.log", "FLASER 3 1.0 1.5 2.0 0 0 0 0 0 0 1.1 h 1.1\n");
  auto run = RunCommand(Slamrig("map " + log + " --out " + dir.File("o") + " --resolution -1"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("resolution_m = -1; must be > 0"));
  run = RunCommand(Slamrig("map " + log + " --out " + dir.File("o") + " --resolution abc"));
  EXPECT_THAT(run.output, HasSubstr("--resolution: expected a number, got 'abc'"));
  run = RunCommand(Slamrig("map " + log));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("--out DIR is required"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("o")));
  // A broken rule about a value from the command line names the flag that set it, for every
  // algorithm's own options.
  for (const char* algorithm : {"pf", "rbpf"}) {
    run = RunCommand(Slamrig("slam " + log + " --algorithm " + algorithm + " --particles 0 --out " +
                             dir.File("o")));
    EXPECT_EQ(run.exit_code, 2) << algorithm;
    EXPECT_THAT(run.output, StartsWith("slamrig: error: --particles 0: particles = 0; must be > 0"))
        << algorithm;
  }
  run = RunCommand(
      Slamrig("slam " + log + " --algorithm rbpf --set weight_exponent=3 --out " + dir.File("o")));
  EXPECT_THAT(run.output, HasSubstr("--set weight_exponent=3: weight_exponent = 3; must be in"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("o")));
  // --perturb: an unknown key or a broken rule is one line naming the key; nothing written.
  run = RunCommand(
      Slamrig("slam " + log + " --perturb odometry.noise_pr_m=1 --out " + dir.File("o")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, StartsWith("slamrig: error: --perturb odometry.noise_pr_m=1: "
                                     "odometry.noise_pr_m: unknown key"));
  EXPECT_EQ(CountLines(run.output), 1) << run.output;
  run = RunCommand(
      Slamrig("slam " + log + " --perturb scans.drop_fraction=2 --out " + dir.File("o")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("scans.drop_fraction = 2; must be in [0, 1]"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("o")));
  // The live view's flags without --live, or with a bad pace: one line, nothing written.
  for (const auto& [flags, message] : std::vector<std::pair<std::string, std::string>>{
           {"--live-wait", "--live-wait needs --live"},
           {"--live-pace 2", "--live-pace needs --live"},
           {"--live 0 --live-pace -1", "--live-pace: expected a number >= 0"}}) {
    run = RunCommand(Slamrig("slam " + log + " " + flags + " --out " + dir.File("o")));
    EXPECT_EQ(run.exit_code, 2) << flags;
    EXPECT_THAT(run.output, HasSubstr(message)) << flags;
    EXPECT_EQ(CountLines(run.output), 1) << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("o"))) << flags;
  }
}

TEST(CliTest, RunWritesAReportAndFailsOnAnUnmetExpectation) {
  TempDir dir;
  // Three seconds of the office scenario, with an impossible map expectation.
  const auto run = RunCommand(Slamrig(std::string("run ") + SLAMRIG_SOURCE_DIR +
                                      "/scenarios/office_loop.yaml --set duration_s=3 "
                                      "--set expect.pf.map_f1_min=1.5 --out " +
                                      dir.File("r")));
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_THAT(run.output, HasSubstr("FAIL   pf.map_f1"));
  EXPECT_THAT(run.output, HasSubstr("under by"));
  EXPECT_THAT(run.output, HasSubstr("office_loop: FAIL -> "));
  for (const char* f : {"report.html", "metrics.json", "config.yaml", "truth.tum", "pf.tum",
                        "map.png", "position_error.png", "neff.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.File(std::string("r/") + f))) << f;
  }
}

// The report's config.yaml is a scenario file: running it repeats the run bit for bit.
TEST(CliTest, TheReportsConfigReproducesTheRun) {
  TempDir dir;
  const auto first = RunCommand(Slamrig(std::string("run ") + SLAMRIG_SOURCE_DIR +
                                        "/scenarios/lidar_blackout.yaml --set duration_s=40 "
                                        "--set slam.pf.particles=20 --quiet --out " +
                                        dir.File("a")));
  ASSERT_EQ(first.exit_code == 0 || first.exit_code == 3, true) << first.output;
  const auto again =
      RunCommand(Slamrig("run " + dir.File("a/config.yaml") + " --quiet --out " + dir.File("b")));
  ASSERT_EQ(again.exit_code, first.exit_code) << again.output;
  // metrics.json equal line for line, the wall-clock figures (and the expectation on one) aside.
  const std::string a = ReadFile(dir.File("a/metrics.json"));
  EXPECT_GT(a.size(), 500u);
  EXPECT_EQ(Without(a, {"realtime_factor", "wall_time_s", "\"value\""}),
            Without(ReadFile(dir.File("b/metrics.json")),
                    {"realtime_factor", "wall_time_s", "\"value\""}));
  EXPECT_EQ(ReadFile(dir.File("a/pf.tum")), ReadFile(dir.File("b/pf.tum")));
  // And the resolved configuration resolves to itself.
  EXPECT_EQ(Without(ReadFile(dir.File("a/config.yaml")), {}),
            Without(ReadFile(dir.File("b/config.yaml")), {}));
}

TEST(CliTest, BadScenarioInputNamesFileLineAndKey) {
  TempDir dir;
  const std::string scenario = dir.Write(
      "bad.yaml", std::string("world: ") + SLAMRIG_SOURCE_DIR +
                      "/worlds/office.yaml\nrobot: " + SLAMRIG_SOURCE_DIR +
                      "/robots/ece276a.yaml\nslam:\n  pf: {algorithm: pf, particels: 10}\n");
  auto run = RunCommand(Slamrig("run " + scenario + " --out " + dir.File("o")));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_EQ(CountLines(run.output), 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr("bad.yaml:4:23: slam.pf.particels: unknown key"));
  run = RunCommand(
      Slamrig("run " + scenario + " --set slam.pf.particles=abc --out " + dir.File("o")));
  EXPECT_THAT(run.output, HasSubstr("expected an integer"));
  // Errors about overridden values name the command-line argument, not a line of the file.
  EXPECT_THAT(run.output,
              StartsWith("slamrig: error: --set slam.pf.particles=abc: slam.pf.particles"));
  run =
      RunCommand(Slamrig("run " + scenario + " --set slam.pf.particles=0 --out " + dir.File("o")));
  EXPECT_THAT(run.output,
              HasSubstr("--set slam.pf.particles=0: slam.pf.particles = 0; must be > 0"));
  run = RunCommand(Slamrig("run " + scenario + " --set world.drive.laps=x --out " + dir.File("o")));
  EXPECT_THAT(run.output, HasSubstr("--set world.drive.laps=x: drive.laps"));
  run = RunCommand(Slamrig("run " + scenario + " --seed -4 --out " + dir.File("o")));
  EXPECT_THAT(run.output, HasSubstr("--seed: expected a non-negative integer"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("o")));
}

}  // namespace
}  // namespace slamrig
