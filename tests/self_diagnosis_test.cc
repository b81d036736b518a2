// Self-diagnosis end to end: the particle filter kidnapped in the office must say it was lost
// (a lost interval at the kidnapping, in metrics.json and the report), `expect: {pf: {lost_max:
// 0}}` must then fail the run and nothing else, and having recovered it must not call its run
// diverged. Graph SLAM on intel's start with doubled odometry noise, which ends 2 m off from one
// failed match, must call itself diverged; on the clean start it must not; nor on intel whole,
// where it must when four times the noise draws the building twice. A gap in seattle's
// odometry must be searched after by the pf and the rbpf.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tests/util/dataset.h"
#include "tests/util/read_file.h"
#include "tests/util/run_command.h"
#include "tests/util/temp_dir.h"

namespace slamrig {
namespace {

using slamrig::testing::ReadFile;

TEST(SelfDiagnosisTest, KidnappedFilterDeclaresItsLostIntervalAndLostMaxZeroFails) {
  testing::TempDir dir;
  const std::string source = SLAMRIG_SOURCE_DIR;
  // scenarios/kidnapping.yaml cut to 75 s: the kidnapping at 60 s and the relocalisation after.
  const std::string scenario = dir.Write(
      "kidnap.yaml", "name: kidnap\nworld: " + source + "/worlds/office.yaml\nrobot: " + source +
                         "/robots/ece276a.yaml\nseed: 1\nduration_s: 75\n"
                         "world_overrides: {drive.laps: 2}\n"
                         "faults:\n  kidnap:\n"
                         "    - {at_s: 60, to: {x_m: 10.0, y_m: 1.25, yaw_rad: 0.0}}\n"
                         "slam:\n  pf: {algorithm: pf, particles: 100}\n"
                         "expect:\n  pf: {lost_max: 0, lost_intervals_min: 1, "
                         "lost_intervals_max: 1, diverged_max: 0}\n");
  const auto run = testing::RunCommand(std::string(SLAMRIG_BINARY) + " run " + scenario +
                                       " --out " + dir.File("out") + " --quiet");
  EXPECT_EQ(run.exit_code, 3) << run.output;  // an expectation failed
  const YAML::Node metrics = YAML::LoadFile(dir.File("out/metrics.json"));
  const YAML::Node pf = metrics["configs"]["pf"];
  EXPECT_EQ(pf["lost"].as<double>(), 1.0);
  EXPECT_EQ(pf["lost_intervals"].as<double>(), 1.0);
  EXPECT_EQ(pf["diverged"].as<double>(), 0.0);
  // The interval starts at the first scan after the kidnapping and ends at the relocalisation.
  ASSERT_EQ(pf["run"]["lost_from_s"].size(), 1u);
  const double from_s = pf["run"]["lost_from_s"][0].as<double>();
  const double to_s = pf["run"]["lost_to_s"][0].as<double>();
  EXPECT_GE(from_s, 60.0);
  EXPECT_LE(from_s, 62.0);
  EXPECT_GT(to_s, from_s);
  EXPECT_LE(to_s, 90.0);
  EXPECT_NEAR(pf["lost_s"].as<double>(), to_s - from_s, 1e-6);
  // lost_max: 0 is the one expectation that fails.
  const YAML::Node expectations = metrics["expectations"];
  EXPECT_FALSE(expectations["pf.lost_max"]["passed"].as<bool>());
  EXPECT_TRUE(expectations["pf.lost_intervals_min"]["passed"].as<bool>());
  EXPECT_TRUE(expectations["pf.lost_intervals_max"]["passed"].as<bool>());
  EXPECT_TRUE(expectations["pf.diverged_max"]["passed"].as<bool>());
  // The report lists the interval.
  EXPECT_NE(ReadFile(dir.File("out/report.html")).find("Self-diagnosis"), std::string::npos);
}

// `slamrig slam` on intel's first 200 scans, perturbed as given; the graph's metrics.
YAML::Node GraphOnIntelStart(const testing::TempDir& dir, const std::string& log,
                             const std::string& name, const std::string& perturb) {
  const auto run = testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " + log +
                                       " --algorithm graph --max-scans 200 --quiet --out " +
                                       dir.File(name) + perturb);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return YAML::LoadFile(dir.File(name + "/metrics.json"))["configs"]["graph"];
}

TEST(SelfDiagnosisTest, GraphCallsAnUnrepairedFrontEndLossDiverged) {
  SLAMRIG_REQUIRE_DATASET(log, "carmen_corrected/intel-corrected.log.gz");
  testing::TempDir dir;
  const YAML::Node clean = GraphOnIntelStart(dir, log, "clean", "");
  EXPECT_LT(clean["ate_rmse_m"].as<double>(), 0.1);
  EXPECT_EQ(clean["lost"].as<double>(), 0.0);
  EXPECT_EQ(clean["diverged"].as<double>(), 0.0);
  // Twice intel's odometry noise and a tenth of the scans dropped: the front end loses its way
  // and says so, and a loop closure spans the loss (the self-calibrated odometry carried it
  // through the blind scans): repaired, not diverged.
  const std::string noisy_odometry =
      " --perturb odometry.noise_per_m=0.131 --perturb odometry.noise_per_rad=0.348";
  const YAML::Node repaired = GraphOnIntelStart(
      dir, log, "repaired", noisy_odometry + " --perturb scans.drop_fraction=0.1");
  EXPECT_LT(repaired["ate_rmse_m"].as<double>(), 0.2);
  EXPECT_GE(repaired["lost_intervals"].as<double>(), 1.0);
  EXPECT_EQ(repaired["unrepaired_losses"].as<double>(), 0.0);
  EXPECT_EQ(repaired["unrepaired_error_bound_m"].as<double>(), 0.0);
  EXPECT_EQ(repaired["diverged"].as<double>(), 0.0);
  // The same with half the scans dropped: a loss no closure spans. (With three in ten dropped
  // the front end's search over a doubted prior now holds the route, 0.10 m.)
  const YAML::Node noisy =
      GraphOnIntelStart(dir, log, "noisy", noisy_odometry + " --perturb scans.drop_fraction=0.5");
  EXPECT_GT(noisy["ate_rmse_m"].as<double>(), 1.0);  // the failure the verdict must see
  EXPECT_GE(noisy["lost_intervals"].as<double>(), 1.0);
  EXPECT_GE(noisy["unrepaired_losses"].as<double>(), 1.0);
  // What the blind stretch may have left, at the odometry noise the front end measured.
  EXPECT_GT(noisy["unrepaired_error_bound_m"].as<double>(), 1.0);
  EXPECT_EQ(noisy["diverged"].as<double>(), 1.0);
}

// Infinite-corridor with twice its odometry noise: at seed 2 the front end takes a turn 92 degrees
// wrong, no loop closure takes it back, and the final trajectory runs its two large loops rotated
// (ATE 70 m) with every edge consistent. Its turns against the
// wheels' say so; at seed 1 (0.52 m) they agree within the wheels' noise.
TEST(SelfDiagnosisTest, GraphCallsATurnTheWheelsDidNotMakeDiverged) {
  SLAMRIG_REQUIRE_DATASET(log, "carmen_corrected/infinite-corridor-corrected.log.gz");
  testing::TempDir dir;
  auto graph = [&](const std::string& seed) {
    const auto run = testing::RunCommand(
        std::string(SLAMRIG_BINARY) + " slam " + log + " --algorithm graph --quiet --seed " + seed +
        " --perturb odometry.noise_per_m=0.0660 --perturb odometry.noise_per_rad=0.1212" +
        " --perturb scans.drop_fraction=0.1 --out " + dir.File(seed));
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return YAML::LoadFile(dir.File(seed + "/metrics.json"))["configs"]["graph"];
  };
  const YAML::Node good = graph("1");
  EXPECT_LT(good["ate_rmse_m"].as<double>(), 1.0);
  EXPECT_EQ(good["wheel_heading_contradiction_rad"].as<double>(), 0.0);
  EXPECT_EQ(good["diverged"].as<double>(), 0.0);
  const YAML::Node failed = graph("2");
  EXPECT_GT(failed["ate_rmse_m"].as<double>(), 1.0);  // the failure the verdict must see
  EXPECT_GT(failed["wheel_heading_contradiction_rad"].as<double>(), 1.0);
  EXPECT_EQ(failed["diverged"].as<double>(), 1.0);
}

// Intel with four times its odometry noise, seed 2: the graph draws the building twice, the
// second copy crossing the first (ATE 11 m), every edge consistent and no turn the wheels (as
// noisy) contradict. Where its final poses come back to a place, the two views share almost
// nothing: the map against itself says so. The clean run agrees at every revisit.
TEST(SelfDiagnosisTest, GraphCallsAMapDrawnTwiceDiverged) {
  SLAMRIG_REQUIRE_DATASET(log, "carmen_corrected/intel-corrected.log.gz");
  testing::TempDir dir;
  auto graph = [&](const std::string& name, const std::string& args) {
    const auto run =
        testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " + log +
                            " --algorithm graph --quiet " + args + " --out " + dir.File(name));
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return YAML::LoadFile(dir.File(name + "/metrics.json"))["configs"]["graph"];
  };
  const YAML::Node clean = graph("clean", "");
  EXPECT_LT(clean["ate_rmse_m"].as<double>(), 0.1);
  EXPECT_GT(clean["revisits"].as<double>(), 100.0);
  EXPECT_EQ(clean["revisits_disagreeing"].as<double>(), 0.0);
  EXPECT_EQ(clean["diverged"].as<double>(), 0.0);
  const YAML::Node twice =
      graph("twice",
            "--seed 2 --perturb odometry.noise_per_m=0.2932 "
            "--perturb odometry.noise_per_rad=0.7789 --perturb scans.drop_fraction=0.1");
  EXPECT_GT(twice["ate_rmse_m"].as<double>(), 1.0);  // the failure the verdict must see
  EXPECT_GE(twice["revisits_disagreeing_places"].as<double>(), 5.0);
  EXPECT_GT(twice["revisits_disagreeing"].as<double>(), 0.01 * twice["revisits"].as<double>());
  EXPECT_EQ(twice["diverged"].as<double>(), 1.0);
}

// Seattle's log has no ODOM line for 3 s while the robot turns 1.4 rad on the spot: the reader
// says so, the synchroniser hands the next scan the odometry's silence, and the pf and the rbpf
// search every heading near by after it (metrics.json's gap_corrections), as ICP odometry does
// its local map. Without the search they went on from a heading 84 degrees off (2.5-3.0 m).
TEST(SelfDiagnosisTest, AfterAGapInTheOdometryThePfAndRbpfFindTheTurnItHid) {
  SLAMRIG_REQUIRE_DATASET(log, "carmen_corrected/seattle-corrected.log.gz");
  testing::TempDir dir;
  auto slam = [&](const std::string& name, const std::string& args) {
    const auto run = testing::RunCommand(std::string(SLAMRIG_BINARY) + " slam " + log + " " + args +
                                         " --quiet --out " + dir.File(name));
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("scan intervals have no raw ODOM line"), std::string::npos)
        << run.output;
    return YAML::LoadFile(dir.File(name + "/metrics.json"))["configs"];
  };
  const YAML::Node pf = slam("pf", "--algorithm pf")["pf"];
  EXPECT_EQ(pf["gap_corrections"].as<double>(), 1.0);
  EXPECT_LT(pf["ate_rmse_m"].as<double>(), 0.3);
  const YAML::Node blind =
      slam("pf_blind", "--algorithm pf --set relocalisation.odometry_gap_s=0")["pf"];
  EXPECT_EQ(blind["gap_corrections"].as<double>(), 0.0);
  EXPECT_GT(blind["ate_rmse_m"].as<double>(), 1.0);
  const YAML::Node rbpf = slam("rbpf", "--algorithm rbpf --particles 10")["rbpf"];
  EXPECT_EQ(rbpf["gap_corrections"].as<double>(), 1.0);
  EXPECT_LT(rbpf["ate_rmse_m"].as<double>(), 0.3);
  // ICP odometry searches its local map over every heading after the gap (2.5 m without).
  const YAML::Node icp = slam("icp", "--algorithm icp-odometry")["icp-odometry"];
  EXPECT_LT(icp["ate_rmse_m"].as<double>(), 0.3);
  const YAML::Node icp_blind =
      slam("icp_blind", "--algorithm icp-odometry --set search.gap_s=0")["icp-odometry"];
  EXPECT_GT(icp_blind["ate_rmse_m"].as<double>(), 1.0);
}

}  // namespace
}  // namespace slamrig
