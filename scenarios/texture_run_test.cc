// The scenario runner with a camera: texture metrics per configuration and for the true poses,
// and the camera's mistakes as one error naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

// A short office run with a small camera; `camera` is extra YAML inside robot_overrides.
std::string WriteScenario(const std::string& name, const std::string& overrides) {
  const std::string dir = testing::TempDir() + "/texture_" + name;
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/s.yaml";
  std::ofstream(path) << "name: " << name << "\nworld: " << SLAMRIG_SOURCE_DIR
                      << "/worlds/office.yaml\nrobot: " << SLAMRIG_SOURCE_DIR
                      << "/robots/ece276a.yaml\nduration_s: 1\n"
                      << "robot_overrides: {camera.width_px: 160, camera.height_px: 120, "
                         "camera.intrinsics.fx_px: 146.25, camera.intrinsics.fy_px: 146.25, "
                         "camera.intrinsics.cx_px: 79.5, camera.intrinsics.cy_px: 59.5"
                      << overrides << "}\ntexture: {pixel_stride: 2}\n"
                      << "slam:\n  dr: {algorithm: dead-reckoning}\n";
  return path;
}

std::string RunError(const std::string& path) {
  const ScenarioSpec spec = LoadScenario(path);
  try {
    RunScenario(spec);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(TextureRunTest, EveryConfigurationAndTheTruthGetTextureMetrics) {
  const ScenarioSpec spec = LoadScenario(WriteScenario("metrics", ""), {"robot.camera.rate_hz=5"});
  ASSERT_TRUE(spec.simulated->options.robot.camera);
  EXPECT_EQ(spec.simulated->options.robot.camera->rate_hz, 5.0);
  // The resolved file carries the camera and the texture block: it repeats the run.
  EXPECT_NE(spec.resolved_yaml.find("rate_hz: 5"), std::string::npos);
  EXPECT_NE(spec.resolved_yaml.find("pixel_stride: 2"), std::string::npos);
  const ScenarioResult r = RunScenario(spec);
  EXPECT_EQ(r.frames, 5);  // 5 Hz over 1 s
  ASSERT_TRUE(r.truth_texture);
  EXPECT_EQ(r.truth_metrics.at("texture_frames"), 5.0);
  EXPECT_GT(r.truth_metrics.at("texture_psnr_db"), 15.0);
  EXPECT_GT(r.truth_metrics.at("texture_coverage"), 0.0);
  ASSERT_EQ(r.configs.size(), 1u);
  const auto& m = r.configs[0].metrics;
  // Dead reckoning over 1 s is close to the truth; its loss is the truth's PSNR minus its own.
  EXPECT_NEAR(m.at("texture_psnr_loss_db"),
              r.truth_metrics.at("texture_psnr_db") - m.at("texture_psnr_db"), 1e-12);
  EXPECT_GE(m.at("texture_frames"), 4.0);
}

TEST(TextureRunTest, ACameraThatSeesNoFloorIsOneErrorNamingIt) {
  // Tilted up: walls, never the floor.
  const std::string up = RunError(WriteScenario("up", ", camera.mount.pitch_rad: -0.6"));
  EXPECT_NE(up.find("s.yaml: robot.camera: "), std::string::npos) << up;
  EXPECT_NE(up.find("not one floor pixel"), std::string::npos) << up;
  // Straight up at the sky: nothing at all, at the first frame.
  const std::string sky = RunError(WriteScenario("sky", ", camera.mount.pitch_rad: -1.5"));
  EXPECT_NE(sky.find("s.yaml: robot.camera: "), std::string::npos) << sky;
  EXPECT_NE(sky.find("sees nothing"), std::string::npos) << sky;
}

TEST(TextureRunTest, AMissingTextureFileIsOneErrorNamingTheFileAndKey) {
  const std::string e = RunError(WriteScenario("missing", ", camera.floor_image: no_such.png"));
  EXPECT_NE(e.find("robot.camera: "), std::string::npos) << e;
  EXPECT_NE(e.find("no_such.png"), std::string::npos) << e;
  EXPECT_NE(e.find("camera.floor_image"), std::string::npos) << e;
}

}  // namespace
}  // namespace slamrig::scenario
