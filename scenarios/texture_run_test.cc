// The scenario runner with a camera: texture metrics per configuration and for the true poses,
// and the camera's mistakes as one error naming the key.
#include "scenarios/texture_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <utility>

#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "sim/camera/camera_test_world.h"
#include "sim/camera/rgbd_camera.h"
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
  // The same map anchored at the start pose (the loss is of the aligned one).
  EXPECT_TRUE(std::isfinite(m.at("texture_psnr_anchored_db")));
  EXPECT_GT(m.at("texture_psnr_anchored_db"), 10.0);
}

// The small room's tiled floor seen by a half-size Kinect along an L-shaped drive: the truth at
// 20 Hz ("scans") and a frame every fourth pose.
struct LDrive {
  TextureRun run;
  Trajectory truth;
};

LDrive DriveAnL() {
  const sim::WorldSpec world = sim::testing::SmallRoom();
  sim::CameraSpec spec;  // tiles.png floor, disparity noise
  spec.width_px = 320;
  spec.height_px = 240;
  spec.intrinsics = {292.5, 292.5, 158.0, 121.5};
  spec.zones.clear();
  sim::RgbdCamera camera(world, spec, 5);
  slam::TextureMapOptions options;
  options.min_m = {-1.0, -2.0};
  options.max_m = {5.0, 2.0};
  options.pixel_stride = 2;
  LDrive d{
      TextureRun(options, camera.floor().TruthColors(options), camera.floor().FloorMask(options)),
      {}};
  for (int k = 0; k <= 120; ++k) {
    // 2.4 m east along y = -1.3, a quarter turn left in place, then 1.2 m north.
    const double s = 0.03 * std::min(k, 80);
    const double turn = std::clamp((k - 80) / 10.0, 0.0, 1.0) * M_PI / 2;
    const double north = 0.04 * std::max(0, k - 90);
    const Pose2 pose(-0.5 + s, -1.3 + north, turn);
    const Time t = Time::FromSeconds(0.05 * k);
    d.truth.Append(t, pose);
    if (k % 4 == 0) d.run.Add(camera.Render(pose, t), pose);
  }
  return d;
}

TEST(TextureRunTest, AlignedScoringUndoesARigidMotionButNotADistortion) {
  const LDrive d = DriveAnL();
  const double truth_db = *d.run.WithTruePoses().score.psnr_db;
  // The true poses at the scans, interpolated at the frames, give the frames' own map.
  EXPECT_NEAR(*d.run.WithPoses(d.truth).score.psnr_db, truth_db, 1e-9);

  // The whole estimate 4 cm and 0.6 degrees off: anchored, the checkered floor loses several dB;
  // aligned as ATE aligns it, nothing.
  const Pose2 offset(0.04, -0.03, 0.01);
  Trajectory moved, bent;
  for (const StampedPose& p : d.truth.poses()) {
    moved.Append(p.time, offset * p.pose);
    // A distortion: an error that grows along the path to 5 cm.
    const double grow = 0.05 * p.time.seconds() / 6.0;
    bent.Append(p.time, Pose2(p.pose.x() + grow, p.pose.y(), p.pose.theta()));
  }
  const TextureResult anchored = d.run.WithPoses(moved);
  const TextureResult aligned = d.run.WithAlignedPoses(moved, d.truth);
  std::printf("true poses %.2f dB, moved %.2f dB anchored, %.2f dB aligned\n", truth_db,
              *anchored.score.psnr_db, *aligned.score.psnr_db);
  EXPECT_LT(*anchored.score.psnr_db, truth_db - 3.0);
  EXPECT_NEAR(*aligned.score.psnr_db, truth_db, 0.05);
  const Pose2 back = aligned.reference_from_estimate * offset;  // identity when undone
  EXPECT_NEAR(back.x(), 0.0, 1e-6);
  EXPECT_NEAR(back.y(), 0.0, 1e-6);
  EXPECT_NEAR(back.theta(), 0.0, 1e-9);

  // A distortion stays: the best rigid motion halves it at most.
  const double bent_db = *d.run.WithAlignedPoses(bent, d.truth).score.psnr_db;
  std::printf("growing error: %.2f dB aligned\n", bent_db);
  EXPECT_LT(bent_db, truth_db - 1.0);
  // Too few pose pairs to align: the poses are used as they are.
  Trajectory one;
  one.Append(d.truth.poses().front().time, offset * d.truth.poses().front().pose);
  EXPECT_EQ(d.run.WithAlignedPoses(one, d.truth).frames, 1);
}

TEST(TextureRunTest, SplitPoseErrorSeparatesAnOffsetFromAlternatingNoise) {
  // 10 s at 10 Hz heading along -x near yaw pi; the estimate is a constant offset plus +-a in x
  // alternating stamp by stamp, and stops 1 s before the truth does.
  const Eigen::Vector3d offset(0.02, -0.01, 0.003);
  const double a = 0.005;
  Trajectory truth, estimate;
  for (int k = 0; k <= 100; ++k) {
    const Time t = Time::FromSeconds(0.1 * k);
    const Pose2 p(-0.5 * 0.1 * k, 1.0, std::numbers::pi - 0.001);
    truth.Append(t, p);
    const double noise = k % 2 == 0 ? a : -a;
    if (k <= 90) {
      estimate.Append(t, Pose2(p.x() + offset.x() + noise, p.y() + offset.y(),
                               p.theta() + offset.z()));  // past pi: wraps to near -pi
    }
  }
  const PoseErrorParts parts = SplitPoseError(estimate, truth, 1.0);
  ASSERT_EQ(parts.slow.size(), 91u);
  ASSERT_EQ(parts.jitter.size(), 91u);
  // Away from the ends the window holds 21 stamps: the alternating noise averages to a / 21.
  for (std::size_t i = 10; i <= 80; ++i) {
    const Pose2& t = truth.poses()[i].pose;
    const Pose2& slow = parts.slow.poses()[i].pose;
    const Pose2& jitter = parts.jitter.poses()[i].pose;
    const double noise = i % 2 == 0 ? a : -a;
    EXPECT_NEAR(slow.x() - t.x(), offset.x() + noise / 21.0, 1e-9) << i;
    EXPECT_NEAR(slow.y() - t.y(), offset.y(), 1e-9) << i;
    EXPECT_NEAR(std::remainder(slow.theta() - t.theta(), 2.0 * std::numbers::pi), offset.z(), 1e-9)
        << i;
    EXPECT_NEAR(jitter.x() - t.x(), noise * 20.0 / 21.0, 1e-9) << i;
    EXPECT_NEAR(jitter.y() - t.y(), 0.0, 1e-9) << i;
    EXPECT_NEAR(std::remainder(jitter.theta() - t.theta(), 2.0 * std::numbers::pi), 0.0, 1e-9) << i;
  }
}

TEST(TextureRunTest, ErrorPartsPutADistortionInSlowAndNoiseInJitter) {
  const LDrive d = DriveAnL();
  const double truth_db = *d.run.WithTruePoses().score.psnr_db;
  // A distortion (an error growing to 5 cm along the path) and white noise of 2 cm and 0.3 deg.
  Trajectory bent, noisy;
  std::mt19937 rng(7);
  std::normal_distribution<double> xy(0.0, 0.02), yaw(0.0, 0.005);
  for (const StampedPose& p : d.truth.poses()) {
    const double grow = 0.05 * p.time.seconds() / 6.0;
    bent.Append(p.time, Pose2(p.pose.x() + grow, p.pose.y(), p.pose.theta()));
    // Sequenced draws, the last coordinate first (the order these cases were generated in).
    const double dtheta = yaw(rng), dy = xy(rng), dx = xy(rng);
    noisy.Append(p.time, Pose2(p.pose.x() + dx, p.pose.y() + dy, p.pose.theta() + dtheta));
  }
  for (const Trajectory* t : {&bent, &noisy}) {
    const double full = truth_db - *d.run.WithAlignedPoses(*t, d.truth).score.psnr_db;
    const std::pair<TextureResult, TextureResult> parts = d.run.WithErrorParts(*t, d.truth, 1.0);
    const double slow = truth_db - *parts.first.score.psnr_db;
    const double jitter = truth_db - *parts.second.score.psnr_db;
    std::printf("%s: loss %.2f dB, slow part alone %.2f dB, jitter alone %.2f dB\n",
                t == &bent ? "distortion" : "noise", full, slow, jitter);
    EXPECT_GT(full, 1.0);
    // The part that carries the error carries its loss; the other costs next to nothing.
    const double carried = t == &bent ? slow : jitter;
    const double other = t == &bent ? jitter : slow;
    EXPECT_NEAR(carried, full, 0.25 * full);
    EXPECT_LT(other, 0.2 * full);
  }
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
