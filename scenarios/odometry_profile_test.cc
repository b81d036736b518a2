// The odometry profiles matched to a real log: robots/odom_intel.yaml simulated on a generated
// office reproduces the intel log's odometry error as `slamrig odometry-noise` measures it
// (per metre travelled, per radian turned, systematic scale), and odom_2x_intel twice it. Six
// 600 s simulations: integration. The method and the figures: docs/studies/odometry-profiles.md.
#include <gtest/gtest.h>

#include <string>

#include "scenarios/recording.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/worldgen/worldgen.h"
#include "slam/config/yaml_node.h"
#include "slam/io/log_perturbation.h"
#include "slam/io/log_reader.h"
#include "tests/util/dataset.h"

namespace slamrig::scenario {
namespace {

// The mean over seeds 1..3 of the profile's odometry error on the generated office (seed 1),
// scans thinned as GMapping thins them (1 m or 0.5 rad), as scripts/odometry_profiles.py runs.
slam::OdometryNoiseMeasurement SimulatedError(const std::string& profile) {
  sim::SimulatorOptions options;
  options.world =
      sim::worldgen::GenerateWorld(YamlNode::LoadString("{kind: office, seed: 1}", "world"));
  options.robot = sim::LoadRobotSpec(sim::FindPresetFile(profile, "robots"));
  RunOptions run;
  run.duration_s = 600.0;
  slam::ScanSyncOptions sync;
  sync.source = slam::OdometrySource::kOdometryPoses;
  slam::OdometryNoiseMeasurement mean;
  mean.scale = mean.rotation_scale = 0.0;
  constexpr int kSeeds = 3;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    options.seed = static_cast<std::uint64_t>(seed);
    const std::string dir = ::testing::TempDir() + "/" + profile + std::to_string(seed);
    RecordSimulation(options, run, dir);
    const slam::OdometryNoiseMeasurement m =
        slam::MeasureOdometryNoise(slam::ReadLog(dir + "/run.log"), sync, {1.0, 0.5});
    mean.noise_per_m += m.noise_per_m / kSeeds;
    mean.rotation_per_m += m.rotation_per_m / kSeeds;
    mean.rotation_per_rad += m.rotation_per_rad / kSeeds;
    mean.scale += m.scale / kSeeds;
    mean.rotation_scale += m.rotation_scale / kSeeds;
  }
  return mean;
}

TEST(OdometryProfileTest, IntelProfilesReproduceIntelsOdometryErrorAndTwiceIt) {
  SLAMRIG_REQUIRE_DATASET(path, "carmen_corrected/intel-corrected.log.gz");
  slam::ScanSyncOptions sync;
  sync.source = slam::OdometrySource::kOdometryPoses;
  const slam::OdometryNoiseMeasurement intel =
      slam::MeasureOdometryNoise(slam::ReadLog(path), sync);
  // The figures of the study, so a change of the measurement shows here too.
  EXPECT_NEAR(intel.noise_per_m, 0.0757, 5e-4);
  EXPECT_NEAR(intel.rotation_per_m, 0.0835, 5e-4);
  EXPECT_NEAR(intel.rotation_per_rad, 0.1216, 5e-4);

  for (const auto& [profile, times] : {std::pair{"odom_intel", 1.0}, {"odom_2x_intel", 2.0}}) {
    SCOPED_TRACE(profile);
    const slam::OdometryNoiseMeasurement sim = SimulatedError(profile);
    EXPECT_NEAR(sim.noise_per_m, times * intel.noise_per_m, 0.15 * times * intel.noise_per_m);
    EXPECT_NEAR(sim.rotation_per_m, times * intel.rotation_per_m,
                0.15 * times * intel.rotation_per_m);
    EXPECT_NEAR(sim.rotation_per_rad, times * intel.rotation_per_rad,
                0.2 * times * intel.rotation_per_rad);
    EXPECT_NEAR(sim.scale - 1.0, times * (intel.scale - 1.0), 0.3 * times * (intel.scale - 1.0));
  }
}

}  // namespace
}  // namespace slamrig::scenario
