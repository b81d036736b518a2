#include "sim/camera/camera_rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "sim/camera/camera_test_world.h"
#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/world_yaml.h"
#include "slam/types/error.h"

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

TEST(CameraRigTest, MovingObstaclesAreInTheFramesWhereTheSimulatorHasThem) {
  // The robot at rest facing a person who walks across its view, 2 m ahead.
  SimulatorOptions o = Office();
  o.world.drive.mode = DriveMode::kIdle;
  const Eigen::Vector2d ahead = o.world.spawn * Eigen::Vector2d(2.0, 0.0);
  const Eigen::Vector2d side(-std::sin(o.world.spawn.theta()), std::cos(o.world.spawn.theta()));
  ObstacleSpec person;
  person.shape.type = ShapeType::kCircle;
  person.shape.radius_m = 0.25;
  person.path_m = {ahead - 2.0 * side, ahead + 2.0 * side};
  person.speed_m_s = 1.0;
  person.loop = false;
  o.world.obstacles = {person};
  CameraSpec spec;
  spec.width_px = 80;
  spec.height_px = 60;
  spec.intrinsics = {73.1, 73.1, 39.5, 29.5};
  spec.floor_texel_m = 0.05;  // a coarse floor texture builds fast
  spec.rate_hz = 10.0;
  spec.mount.pitch_rad = 0.0;
  spec.mount.yaw_rad = 0.0;
  spec.depth_offset_x_m = 0.0;
  spec.depth_model = DepthModel::kIdeal;
  Simulator sim(o);
  CameraRig rig(&sim, spec, 5);
  std::vector<TruthSample> truth;
  const std::vector<Record> records = Drive(sim, &rig, 4.0, &truth);
  int near = 0, far = 0;
  for (const Record& r : records) {
    const auto* f = std::get_if<RgbdFrame>(&r);
    if (f == nullptr) continue;
    const double centre = f->depth_m[29 * 80 + 39];
    // Straight ahead: the person's near side (2 - 0.25 - 0.18 m from the camera) while crossing
    // in front, else whatever lies beyond.
    const Eigen::Vector2d p = sim.world().ObstaclePositionAt(0, f->time);
    const double offset = std::abs(side.dot(p - ahead));
    if (offset < 0.1) {
      EXPECT_NEAR(centre, 2.0 - 0.25 - 0.18, 0.05) << f->time.seconds();
      ++near;
    } else if (offset > 0.4) {
      EXPECT_TRUE(centre == 0.0 || centre > 2.0) << f->time.seconds() << ": " << centre;
      ++far;
    }
  }
  EXPECT_GE(near, 1);
  EXPECT_GE(far, 10);
}

TEST(CameraRigTest, ACameraWithoutAnyDepthReadingIsAnError) {
  SimulatorOptions o = Office();
  CameraSpec spec;
  spec.width_px = 80;
  spec.height_px = 60;
  spec.intrinsics = {73.1, 73.1, 39.5, 29.5};
  spec.floor_texel_m = 0.05;  // a coarse floor texture builds fast
  spec.min_depth_m = 0.1;
  spec.max_depth_m = 0.2;  // nothing is that near
  Simulator sim(o);
  CameraRig rig(&sim, spec, 5);
  try {
    std::vector<TruthSample> truth;
    Drive(sim, &rig, 1.0, &truth);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("camera 'kinect': no depth reading in any pixel of the "
                                         "first frame, t = 0.1 s"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("camera.max_depth_m = 0.2"), std::string::npos);
  }
}

TEST(CameraRigTest, TextureFolderIsRelativeToTheRobotFile) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "robot_tex";
  std::filesystem::remove_all(dir);
  testing::WriteSolidPng((dir / "my_textures").string(), "grey.png", {90, 90, 90});
  const auto write = [&](const std::string& name, const std::string& camera) {
    std::ifstream in(FindPresetFile("ece276a", "robots"));
    std::stringstream yaml;
    yaml << in.rdbuf() << "camera:\n" << camera;
    std::ofstream((dir / name).string()) << yaml.str();
    return (dir / name).string();
  };
  const RobotSpec robot = LoadRobotSpec(
      write("ok.yaml", "  texture_dir: my_textures\n  floor_image: grey.png\n  wall_image: ''\n"));
  EXPECT_EQ(robot.camera->texture_dir, (dir / "my_textures").string());
  // A folder that is not there is the robot file's error, at its line.
  const std::string bad = write("bad.yaml", "  texture_dir: no_such_folder\n");
  try {
    LoadRobotSpec(bad);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(bad + ":"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("camera.texture_dir"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no_such_folder"), std::string::npos) << e.what();
  }
  // A missing image in that folder names the file and the key.
  const RobotSpec missing = LoadRobotSpec(write("missing.yaml", "  texture_dir: my_textures\n"));
  try {
    RgbdCamera camera(Office().world, *missing.camera);
    FAIL() << "expected a ParseError";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "my_textures" / "tiles.png").string() +
                                         ": camera.floor_image: texture file not found"),
              std::string::npos)
        << e.what();
  }
}

TEST(CameraRigTest, TextureFolderOnTheCommandLineIsRelativeToTheWorkingDirectory) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / "robot_tex_cwd";
  fs::remove_all(dir);
  // The robot file in one folder, the textures in a folder beside it, the working directory the
  // textures' parent: "cwd_textures" exists from the working directory only.
  fs::create_directories(dir / "robots");
  testing::WriteSolidPng((dir / "work" / "cwd_textures").string(), "grey.png", {90, 90, 90});
  const fs::path robot_file = dir / "robots" / "robot.yaml";
  {
    std::ifstream in(FindPresetFile("ece276a", "robots"));
    std::ofstream out(robot_file.string());
    out << in.rdbuf() << "camera:\n  floor_image: grey.png\n  wall_image: ''\n";
  }
  const fs::path cwd = fs::current_path();
  fs::current_path(dir / "work");
  const auto parse = [&](const std::string& origin) {
    YamlNode root = YamlNode::LoadFile(robot_file.string());
    root.Override("camera.texture_dir", "cwd_textures", origin);
    return ParseRobotSpec(root);
  };
  std::optional<RobotSpec> from_command_line;
  std::string file_error;
  try {
    from_command_line = parse("--set robot.camera.texture_dir=cwd_textures");
    // Without an origin the override is the file's own, and relative to it: not there.
    parse("");
  } catch (const ConfigError& e) {
    file_error = e.what();
  }
  fs::current_path(cwd);
  ASSERT_TRUE(from_command_line.has_value()) << file_error;
  EXPECT_EQ(from_command_line->camera->texture_dir, (dir / "work" / "cwd_textures").string());
  EXPECT_NE(file_error.find((dir / "robots" / "cwd_textures").string()), std::string::npos)
      << file_error;
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
