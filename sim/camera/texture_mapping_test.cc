// The camera and the texture map together: a short straight drive through a small world with the
// true poses gives a texture map that matches the world's floor.
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "sim/camera/camera_test_world.h"
#include "sim/camera/rgbd_camera.h"
#include "slam/texture/texture_map.h"
#include "slam/texture/texture_score.h"

namespace slamrig::sim {
namespace {

TEST(TextureMappingTest, StraightDriveWithTruePosesMatchesTheFloor) {
  // A 6 m x 4 m room, tiled floor and a carpet zone, the default Kinect (disparity noise on) at
  // half resolution.
  WorldSpec world;
  world.name = "tiny";
  world.walls = {testing::Box(3.0, -0.1, 6.2, 0.2), testing::Box(3.0, 4.1, 6.2, 0.2),
                 testing::Box(-0.1, 2.0, 0.2, 4.2), testing::Box(6.1, 2.0, 0.2, 4.2)};
  ZoneSpec carpet;
  carpet.name = "carpet";
  carpet.shape = testing::Box(3.5, 2.0, 1.5, 4.0);
  world.zones = {carpet};
  CameraSpec spec;
  spec.width_px = 320;
  spec.height_px = 240;
  spec.intrinsics = {292.5, 292.5, 158.0, 121.5};
  RgbdCamera camera(world, spec, 3);

  slam::TextureMapOptions options;
  options.resolution_m = 0.05;
  options.min_m = {0.0, 0.0};
  options.max_m = {6.0, 4.0};
  slam::TextureMap map(options);
  // 0.4 m/s along y = 2 for 8 s at the camera's 10 Hz.
  std::vector<std::pair<Pose2, RgbdFrame>> frames;
  for (int k = 0; k <= 80; ++k) {
    const double t = k * spec.period_s();
    const Pose2 pose(0.5 + 0.4 * t, 2.0, 0.0);
    frames.emplace_back(pose, camera.Render(pose, Time::FromSeconds(t)));
  }
  int added = 0;
  for (const auto& [pose, frame] : frames) added += map.Insert(frame, pose);
  EXPECT_GT(added, 0);
  const slam::TextureScore score =
      slam::ScoreTexture(map.Colors(), map.Observed(), camera.floor().TruthColors(options),
                         camera.floor().FloorMask(options));
  ASSERT_TRUE(score.psnr_db.has_value());
  std::printf("straight drive: PSNR %.2f dB, mean abs error %.2f, coverage %.3f (%d of %d)\n",
              *score.psnr_db, *score.mean_abs_error, score.coverage, score.observed_cells,
              score.floor_cells);
  EXPECT_GE(*score.psnr_db, 20.0);
  EXPECT_GT(score.coverage, 0.3);

  // The same drive with the poses 0.3 m off: the map no longer matches (the score can fail).
  slam::TextureMap shifted(options);
  for (const auto& [pose, frame] : frames) {
    shifted.Insert(frame, Pose2(pose.x() + 0.3, pose.y() + 0.1, 0.0));
  }
  const slam::TextureScore bad =
      slam::ScoreTexture(shifted.Colors(), shifted.Observed(), camera.floor().TruthColors(options),
                         camera.floor().FloorMask(options));
  std::printf("shifted poses: PSNR %.2f dB\n", *bad.psnr_db);
  EXPECT_LT(*bad.psnr_db, *score.psnr_db - 3.0);
}

}  // namespace
}  // namespace slamrig::sim
