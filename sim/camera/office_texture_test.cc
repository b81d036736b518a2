// Integration: the office world driven by the simulator, the reports' Kinect at 10 Hz on the true
// poses, texture-mapped and scored against the world's floor texture.
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/camera/rgbd_camera.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world_yaml.h"
#include "slam/texture/texture_map.h"
#include "slam/texture/texture_score.h"

namespace slamrig::sim {
namespace {

TEST(OfficeTextureTest, OneLapWithTruePosesAtTenHertz) {
  SimulatorOptions options;
  options.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  options.robot = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  options.world.drive.laps = 1;
  Simulator sim(options);
  const CameraSpec spec;  // the reports' Kinect, 640 x 480, disparity noise
  RgbdCamera camera(options.world, spec, 1);

  slam::TextureMapOptions map_options;
  map_options.min_m = {-0.5, -0.5};
  map_options.max_m = {24.5, 16.5};
  map_options.pixel_stride = 2;
  slam::TextureMap map(map_options);
  Time next_frame = sim.time();
  int frames = 0;
  constexpr double kMaxSeconds = 400.0;
  while (!sim.drive_finished() && sim.time().seconds() < kMaxSeconds) {
    sim.Step();
    if (sim.time() < next_frame) continue;
    const Pose2 pose = sim.Truth().map_from_base;
    map.Insert(camera.Render(pose, sim.time()), pose);
    ++frames;
    next_frame = AddSeconds(next_frame, spec.period_s());
  }
  ASSERT_GT(frames, 100);
  const cv::Mat3b truth = camera.floor().TruthColors(map_options);
  const slam::TextureScore score = slam::ScoreTexture(map.Colors(), map.Observed(), truth,
                                                      camera.floor().FloorMask(map_options));
  ASSERT_TRUE(score.psnr_db.has_value());
  std::printf("office, %d frames over %.0f s: PSNR %.2f dB, mean abs error %.2f, coverage %.3f\n",
              frames, sim.time().seconds(), *score.psnr_db, *score.mean_abs_error, score.coverage);
  EXPECT_GE(*score.psnr_db, 20.0);
  // The robot keeps to the corridor loop: most of the rooms stay unseen.
  EXPECT_GT(score.coverage, 0.15);

  // For people: the map beside the truth.
  cv::Mat both, bgr;
  cv::hconcat(map.Colors(), truth, both);
  cv::cvtColor(both, bgr, cv::COLOR_RGB2BGR);
  const std::string path = ::testing::TempDir() + "/office_texture_map.png";
  cv::imwrite(path, bgr);
  std::printf("texture map and truth: %s\n", path.c_str());
}

}  // namespace
}  // namespace slamrig::sim
