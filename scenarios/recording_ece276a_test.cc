// `slamrig simulate --format ece276a` end to end: a simulated office run with the Kinect written in
// the ECE276A layout and read back by slam::ReadEce276a gives the records that were simulated,
// and a texture map from the read-back frames is the one from the frames in memory.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "scenarios/recording.h"
#include "sim/camera/camera_rig.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/io/ece276a_reader.h"
#include "slam/texture/texture_map.h"
#include "slam/texture/texture_score.h"

namespace slamrig::scenario {
namespace {

sim::SimulatorOptions OfficeWithKinect() {
  sim::SimulatorOptions o;
  o.world = sim::LoadWorldSpec(sim::FindPresetFile("office", "worlds"));
  o.robot = sim::LoadRobotSpec(sim::FindPresetFile("ece276a", "robots"));
  sim::CameraSpec camera;  // the ECE276A Kinect (disparity noise, depth offset) at quarter size
  camera.width_px = 160;
  camera.height_px = 120;
  camera.rate_hz = 5.0;
  camera.intrinsics = {146.26, 146.26, 78.96, 60.74};
  o.robot.camera = camera;
  o.seed = 5;
  return o;
}

struct InMemory {
  std::vector<Record> records;
  std::vector<sim::TruthSample> truth;
};

// The run RecordSimulation makes, kept in memory (its loop, its order of steps).
InMemory Simulate(const sim::SimulatorOptions& options, double duration_s) {
  sim::Simulator sim(options);
  sim::CameraRig rig(&sim, *options.robot.camera, options.seed);
  InMemory out;
  const auto keep = [&](sim::StepResult step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      out.records.push_back(std::move(step.records[i]));
      out.truth.push_back(step.truth[i]);
    }
  };
  while (sim.time().seconds() < duration_s - 0.5 * sim.step_s()) keep(rig.Step());
  keep(rig.Flush());
  return out;
}

template <typename T>
std::vector<const T*> All(const std::vector<Record>& records) {
  std::vector<const T*> out;
  for (const Record& r : records) {
    if (const auto* x = std::get_if<T>(&r)) out.push_back(x);
  }
  return out;
}

TEST(Ece276aRecordingTest, SimulatedRunReadsBackAsTheSimulatedRecords) {
  const sim::SimulatorOptions options = OfficeWithKinect();
  constexpr double kDurationS = 6.0;
  const std::string dir = ::testing::TempDir() + "/ece276a_recording";
  std::filesystem::remove_all(dir);
  RunOptions run;
  run.duration_s = kDurationS;
  RecordingOptions recording;
  recording.format = RecordingFormat::kEce276a;
  recording.ece276a_dataset = 3;
  const RunSummary summary = RecordSimulation(options, run, dir, recording);
  const InMemory sim = Simulate(options, kDurationS);

  // What the layout does not hold comes from the robot, as a user of the reports' code knows it.
  const sim::CameraSpec& camera = *options.robot.camera;
  const sim::RgbdCamera probe(options.world, camera, options.seed);
  slam::Ece276aReadOptions read;
  read.base_from_lidar = Pose2(options.robot.lidar.mount.x_m, options.robot.lidar.mount.y_m,
                               options.robot.lidar.mount.yaw_rad);
  read.camera_intrinsics = probe.intrinsics();
  read.base_from_camera = camera.mount;
  read.depth_offset_x_m = camera.depth_offset_x_m;
  const slam::Dataset back = slam::ReadEce276a(slam::FindEce276aFiles(dir + "/3"), read);

  const auto ticks = All<WheelTicks>(sim.records), ticks_back = All<WheelTicks>(back.records);
  ASSERT_EQ(ticks.size(), ticks_back.size());
  ASSERT_GT(ticks.size(), 200u);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_EQ(ticks_back[i]->time, ticks[i]->time);
    EXPECT_EQ(ticks_back[i]->right_ticks, ticks[i]->right_ticks);
    EXPECT_EQ(ticks_back[i]->left_ticks, ticks[i]->left_ticks);
  }
  const auto imu = All<ImuSample>(sim.records), imu_back = All<ImuSample>(back.records);
  ASSERT_EQ(imu.size(), imu_back.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    EXPECT_EQ(imu_back[i]->time, imu[i]->time);
    EXPECT_EQ(imu_back[i]->angular_velocity_rad_s, imu[i]->angular_velocity_rad_s);
    // Stored in g: one division and one multiplication by the same constant.
    EXPECT_LT((imu_back[i]->linear_acceleration_m_s2 - imu[i]->linear_acceleration_m_s2).norm(),
              1e-13);
  }
  const auto scans = All<LaserScan>(sim.records), scans_back = All<LaserScan>(back.records);
  ASSERT_EQ(scans.size(), scans_back.size());
  EXPECT_EQ(static_cast<int>(scans.size()), summary.num_scans);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    EXPECT_EQ(scans_back[i]->time, scans[i]->time);
    EXPECT_EQ(scans_back[i]->ranges_m, scans[i]->ranges_m);
    EXPECT_EQ(scans_back[i]->angle_min_rad, scans[i]->angle_min_rad);
    EXPECT_NEAR(scans_back[i]->angle_increment_rad, scans[i]->angle_increment_rad, 1e-15);
    EXPECT_EQ(scans_back[i]->range_max_m, scans[i]->range_max_m);
    EXPECT_EQ(scans_back[i]->base_from_laser.translation(),
              scans[i]->base_from_laser.translation());
  }
  // Frames: the colour bytes exactly; the depth through the integer disparity the simulated
  // Kinect already quantized to, so exactly too.
  std::vector<std::pair<const RgbdFrame*, Pose2>> frames;
  for (std::size_t i = 0; i < sim.records.size(); ++i) {
    if (const auto* f = std::get_if<RgbdFrame>(&sim.records[i])) {
      frames.emplace_back(f, sim.truth[i].map_from_base);
    }
  }
  const auto frames_back = All<RgbdFrame>(back.records);
  ASSERT_EQ(frames.size(), frames_back.size());
  ASSERT_EQ(static_cast<int>(frames.size()), summary.num_frames);
  ASSERT_GE(frames.size(), 29u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const RgbdFrame& a = *frames[i].first;
    const RgbdFrame& b = *frames_back[i];
    EXPECT_EQ(b.time, a.time);
    ASSERT_EQ(b.width, a.width);
    ASSERT_EQ(b.height, a.height);
    EXPECT_EQ(b.rgb, a.rgb) << "frame " << i;
    EXPECT_EQ(b.depth_m, a.depth_m) << "frame " << i;
    EXPECT_EQ(b.intrinsics.cx_px, a.intrinsics.cx_px);
    EXPECT_TRUE(b.BaseFromDepthOptical().isApprox(a.BaseFromDepthOptical(), 1e-15));
  }
  for (std::size_t i = 1; i < back.records.size(); ++i) {
    ASSERT_FALSE(RecordTime(back.records[i]) < RecordTime(back.records[i - 1])) << i;
  }

  // The texture map from the read-back frames (true poses) against the one from memory.
  slam::TextureMapOptions map_options;
  map_options.resolution_m = 0.05;
  map_options.min_m = {-2.0, -2.0};
  map_options.max_m = {14.0, 10.0};
  slam::TextureMap from_memory(map_options), from_files(map_options);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    from_memory.Insert(*frames[i].first, frames[i].second);
    from_files.Insert(*frames_back[i], frames[i].second);
  }
  const slam::TextureScore same = slam::ScoreTexture(from_files.Colors(), from_files.Observed(),
                                                     from_memory.Colors(), from_memory.Observed());
  ASSERT_TRUE(same.psnr_db.has_value());
  const slam::TextureScore truth = slam::ScoreTexture(from_files.Colors(), from_files.Observed(),
                                                      probe.floor().TruthColors(map_options),
                                                      probe.floor().FloorMask(map_options));
  std::printf(
      "read-back texture map: %d cells, PSNR %.1f dB against the in-memory map, %.1f dB "
      "against the true floor\n",
      same.observed_cells, *same.psnr_db, truth.psnr_db.value_or(-1.0));
  EXPECT_GT(same.observed_cells, 500);
  EXPECT_EQ(same.coverage, 1.0);
  EXPECT_GE(*same.psnr_db, 60.0);
}

}  // namespace
}  // namespace slamrig::scenario
