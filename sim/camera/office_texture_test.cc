// Integration: the office world driven by the simulator, the reports' Kinect at 10 Hz on the true
// poses, texture-mapped and scored against the world's floor texture.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <variant>
#include <vector>

#include "sim/camera/rgbd_camera.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world_yaml.h"
#include "slam/texture/texture_map.h"
#include "slam/texture/texture_score.h"
#include "slam/types/trajectory.h"

namespace slamrig::sim {
namespace {

/// One lap of the office with the default Kinect at 10 Hz: each frame's floor pixels and the
/// true pose at its time, and the true poses at the lidar's scan stamps (what an estimator's
/// trajectory is sampled at).
struct OfficeLap {
  slam::TextureMapOptions map_options;
  cv::Mat3b truth;
  cv::Mat1b floor;
  std::vector<slam::FloorPixels> pixels;
  std::vector<Pose2> frame_poses;
  Trajectory at_scans;
  double seconds = 0.0;
};

OfficeLap DriveOneLap() {
  SimulatorOptions options;
  options.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  options.robot = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  options.world.drive.laps = 1;
  Simulator sim(options);
  const CameraSpec spec;  // the reports' Kinect, 640 x 480, disparity noise
  RgbdCamera camera(options.world, spec, 1);

  OfficeLap lap;
  lap.map_options.min_m = {-0.5, -0.5};
  lap.map_options.max_m = {24.5, 16.5};
  lap.map_options.pixel_stride = 4;  // the scenario runner's default
  Time next_frame = sim.time();
  constexpr double kMaxSeconds = 400.0;
  while (!sim.drive_finished() && sim.time().seconds() < kMaxSeconds) {
    const StepResult step = sim.Step();
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      if (const auto* scan = std::get_if<LaserScan>(&step.records[i])) {
        lap.at_scans.Append(scan->time, step.truth[i].map_from_base);
      }
    }
    if (sim.time() < next_frame) continue;
    const Pose2 pose = sim.Truth().map_from_base;
    lap.pixels.push_back(
        slam::ExtractFloorPixels(camera.Render(pose, sim.time()), lap.map_options));
    lap.frame_poses.push_back(pose);
    next_frame = AddSeconds(next_frame, spec.period_s());
  }
  lap.seconds = sim.time().seconds();
  lap.truth = camera.floor().TruthColors(lap.map_options);
  lap.floor = camera.floor().FloorMask(lap.map_options);
  return lap;
}

// The lap is driven once for every test here (rendering it takes most of a minute).
const OfficeLap& TheLap() {
  static const OfficeLap lap = DriveOneLap();
  return lap;
}

// The lap's frames mapped at pose(k) for frame k.
slam::TextureScore MapWith(const OfficeLap& lap, const std::function<Pose2(std::size_t)>& pose) {
  slam::TextureMap map(lap.map_options);
  for (std::size_t k = 0; k < lap.pixels.size(); ++k) map.Insert(lap.pixels[k], pose(k));
  return slam::ScoreTexture(map.Colors(), map.Observed(), lap.truth, lap.floor);
}

TEST(OfficeTextureTest, OneLapWithTruePosesAtTenHertz) {
  const OfficeLap& lap = TheLap();
  ASSERT_GT(lap.pixels.size(), 100u);
  slam::TextureMap map(lap.map_options);
  for (std::size_t k = 0; k < lap.pixels.size(); ++k) map.Insert(lap.pixels[k], lap.frame_poses[k]);
  const slam::TextureScore score =
      slam::ScoreTexture(map.Colors(), map.Observed(), lap.truth, lap.floor);
  ASSERT_TRUE(score.psnr_db.has_value());
  std::printf("office, %zu frames over %.0f s: PSNR %.2f dB, mean abs error %.2f, coverage %.3f\n",
              lap.pixels.size(), lap.seconds, *score.psnr_db, *score.mean_abs_error,
              score.coverage);
  EXPECT_GE(*score.psnr_db, 20.0);
  // The robot keeps to the corridor loop: most of the rooms stay unseen.
  EXPECT_GT(score.coverage, 0.15);

  // For people: the map beside the truth.
  cv::Mat both, bgr;
  cv::hconcat(map.Colors(), lap.truth, both);
  cv::cvtColor(both, bgr, cv::COLOR_RGB2BGR);
  const std::string path = ::testing::TempDir() + "/office_texture_map.png";
  cv::imwrite(path, bgr);
  std::printf("texture map and truth: %s\n", path.c_str());
}

// How much PSNR a pose error costs on the office's floor (checkered 25 cm tiles, 5 cm cells),
// which says how precise an estimator must be for a texture map within a few dB of the truth's.
// Also checks the timing the scenario runner relies on: the true poses sampled at the scan stamps
// and interpolated at the frame stamps give the same map as the poses the frames were taken at.
TEST(OfficeTextureTest, PsnrLossGrowsWithThePoseError) {
  const OfficeLap& lap = TheLap();
  ASSERT_GT(lap.pixels.size(), 100u);
  const slam::TextureScore exact = MapWith(lap, [&](std::size_t k) { return lap.frame_poses[k]; });
  ASSERT_TRUE(exact.psnr_db.has_value());
  const double reference = *exact.psnr_db;
  std::printf("true poses at the frames: %.2f dB\n", reference);

  // The first frame (at t = 0) may come before the first scan's stamp: it keeps its pose.
  double worst_interpolation_m = 0.0;
  int outside = 0;
  const slam::TextureScore interpolated = MapWith(lap, [&](std::size_t k) {
    const std::optional<Pose2> p = lap.at_scans.Interpolate(lap.pixels[k].time);
    if (!p) {
      ++outside;
      return lap.frame_poses[k];
    }
    worst_interpolation_m = std::max(worst_interpolation_m,
                                     (p->translation() - lap.frame_poses[k].translation()).norm());
    return *p;
  });
  std::printf("true poses at the scans, interpolated at the frames: %.2f dB (worst %.2f mm)\n",
              *interpolated.psnr_db, 1e3 * worst_interpolation_m);
  EXPECT_LE(outside, 1);
  EXPECT_LT(worst_interpolation_m, 2e-3);
  EXPECT_NEAR(*interpolated.psnr_db, reference, 0.1);

  // A constant offset along x, and one that drifts around a circle of that radius over a minute
  // (as an estimator's error does), in metres; a constant heading error, in degrees.
  auto loss = [&](const std::function<Pose2(std::size_t)>& pose) {
    return reference - *MapWith(lap, pose).psnr_db;
  };
  std::vector<double> shift_loss, drift_loss, yaw_loss;
  for (const double d : {0.01, 0.02, 0.05}) {
    shift_loss.push_back(loss([&](std::size_t k) {
      const Pose2& p = lap.frame_poses[k];
      return Pose2(p.x() + d, p.y(), p.theta());
    }));
    drift_loss.push_back(loss([&](std::size_t k) {
      const Pose2& p = lap.frame_poses[k];
      const double a = 2.0 * std::numbers::pi * lap.pixels[k].time.seconds() / 60.0;
      return Pose2(p.x() + d * std::cos(a), p.y() + d * std::sin(a), p.theta());
    }));
    std::printf("offset %.0f cm: loss %.2f dB constant along x, %.2f dB drifting\n", 100 * d,
                shift_loss.back(), drift_loss.back());
  }
  for (const double deg : {0.1, 0.3, 1.0}) {
    yaw_loss.push_back(loss([&](std::size_t k) {
      const Pose2& p = lap.frame_poses[k];
      return Pose2(p.x(), p.y(), p.theta() + deg * std::numbers::pi / 180.0);
    }));
    std::printf("heading %.1f deg: loss %.2f dB\n", deg, yaw_loss.back());
  }
  for (std::size_t i = 0; i + 1 < shift_loss.size(); ++i) {
    EXPECT_LT(shift_loss[i], shift_loss[i + 1]);
    EXPECT_LT(drift_loss[i], drift_loss[i + 1]);
    EXPECT_LT(yaw_loss[i], yaw_loss[i + 1]);
  }
  // A centimetre is affordable, five are not: on 25 cm tiles a 5 cm shift misplaces a fifth of
  // each tile's cells along that axis.
  EXPECT_LT(shift_loss.front(), 3.0);
  EXPECT_GT(shift_loss[1], 1.5);
  EXPECT_GT(shift_loss.back(), 6.0);
  EXPECT_GT(drift_loss.back(), 6.0);
  EXPECT_LT(yaw_loss.front(), 1.0);
}

}  // namespace
}  // namespace slamrig::sim
