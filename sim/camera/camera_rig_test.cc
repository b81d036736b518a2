#include "sim/camera/camera_rig.h"

#include <gtest/gtest.h>

#include <vector>

#include "sim/camera/camera_test_world.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"

namespace slamrig::sim {
namespace {

SimulatorOptions Office() {
  SimulatorOptions o;
  o.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  o.robot = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  o.seed = 5;
  return o;
}

std::vector<Record> Drive(Simulator& sim, CameraRig* rig, double seconds,
                          std::vector<TruthSample>* truth) {
  std::vector<Record> records;
  auto take = [&](StepResult step) {
    for (std::size_t i = 0; i < step.records.size(); ++i) {
      records.push_back(std::move(step.records[i]));
      truth->push_back(step.truth[i]);
    }
  };
  while (sim.time().seconds() < seconds) take(rig ? rig->Step() : sim.Step());
  take(rig ? rig->Flush() : sim.Flush());
  return records;
}

TEST(CameraRigTest, FramesJoinTheStreamInTimeOrderAndChangeNoOtherRecord) {
  CameraSpec camera = testing::IdealCamera(::testing::TempDir() + "/rig_textures");
  camera.rate_hz = 10.0;
  Simulator with_sim(Office());
  CameraRig rig(&with_sim, camera, 5);
  std::vector<TruthSample> truth_with, truth_without;
  const std::vector<Record> with = Drive(with_sim, &rig, 2.0, &truth_with);
  Simulator without_sim(Office());
  const std::vector<Record> without = Drive(without_sim, nullptr, 2.0, &truth_without);

  // Time order over the whole stream, frames included; frame k at k / 10 s (physics at 200 Hz).
  std::vector<Record> others;
  std::vector<std::int64_t> frame_ns;
  for (std::size_t i = 0; i < with.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(RecordTime(with[i - 1]).ns, RecordTime(with[i]).ns) << i;
    }
    if (const auto* f = std::get_if<RgbdFrame>(&with[i])) {
      frame_ns.push_back(f->time.ns);
      EXPECT_EQ(truth_with[i].time, f->time);
      EXPECT_EQ(f->width, camera.width_px);
    } else {
      others.push_back(with[i]);
    }
  }
  ASSERT_EQ(frame_ns.size(), 20u);
  for (std::size_t k = 0; k < frame_ns.size(); ++k)
    EXPECT_EQ(frame_ns[k], static_cast<std::int64_t>(k + 1) * 100'000'000) << k;
  EXPECT_EQ(rig.frames(), 20);

  // Every other record bit for bit as without the camera.
  ASSERT_EQ(others.size(), without.size());
  for (std::size_t i = 0; i < others.size(); ++i) {
    ASSERT_EQ(others[i].index(), without[i].index()) << i;
    EXPECT_EQ(RecordTime(others[i]), RecordTime(without[i])) << i;
    if (const auto* s = std::get_if<LaserScan>(&others[i])) {
      EXPECT_EQ(s->ranges_m, std::get<LaserScan>(without[i]).ranges_m) << i;
    }
    if (const auto* imu = std::get_if<ImuSample>(&others[i])) {
      EXPECT_EQ(imu->angular_velocity_rad_s,
                std::get<ImuSample>(without[i]).angular_velocity_rad_s);
    }
  }
}

TEST(CameraRigTest, TheRobotFileCarriesTheCameraAndWritesItBack) {
  RobotSpec robot = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  EXPECT_FALSE(robot.camera.has_value());
  robot.camera.emplace();
  robot.camera->rate_hz = 7.5;
  robot.camera->wall_rgb = {0.1, 0.2, 0.3};
  robot.camera->zones = {{"rug", "carpet.png", 0.5}};
  const std::string path = ::testing::TempDir() + "/robot_with_camera.yaml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    const std::string yaml = RobotSpecToYaml(robot);
    std::fwrite(yaml.data(), 1, yaml.size(), f);
    std::fclose(f);
  }
  const RobotSpec back = LoadRobotSpec(path);
  ASSERT_TRUE(back.camera.has_value());
  EXPECT_EQ(back.camera->rate_hz, 7.5);
  EXPECT_EQ(back.camera->wall_rgb, robot.camera->wall_rgb);
  ASSERT_EQ(back.camera->zones.size(), 1u);
  EXPECT_EQ(back.camera->zones[0].zone, "rug");
  EXPECT_EQ(back.camera->zones[0].tile_m, 0.5);
  EXPECT_EQ(RobotSpecToYaml(back), RobotSpecToYaml(robot));
}

}  // namespace
}  // namespace slamrig::sim
