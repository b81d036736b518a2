#include "sim/world_yaml.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "slam/types/error.h"

namespace slamrig::sim {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

std::string WriteFile(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// The one-line error a bad file gives.
std::string ErrorOf(const std::function<void()>& load) {
  try {
    load();
  } catch (const ConfigError& e) {
    return e.what();
  } catch (const ParseError& e) {
    return e.what();
  }
  return "no error";
}

constexpr const char* kGoodWorld = R"(name: t
spawn: {x_m: 1.0, y_m: 1.0, yaw_rad: 0.0}
walls:
  - {type: box, center_m: [5.0, 0.0], size_m: [10.0, 0.2]}
zones:
  - name: ice
    shape: {type: circle, center_m: [2.0, 2.0], radius_m: 1.0}
    mu: 0.1
)";

TEST(WorldYamlTest, ReadsAGoodWorld) {
  const WorldSpec spec = LoadWorldSpec(WriteFile("good.yaml", kGoodWorld));
  ASSERT_EQ(spec.walls.size(), 1u);
  EXPECT_EQ(spec.walls[0].size_m, Eigen::Vector2d(10.0, 0.2));
  ASSERT_EQ(spec.zones.size(), 1u);
  EXPECT_EQ(spec.zones[0].surface.mu, 0.1);
  EXPECT_EQ(spec.zones[0].surface.rolling_resistance, SurfaceSpec{}.rolling_resistance);
  EXPECT_EQ(spec.spawn, Pose2(1.0, 1.0, 0.0));
}

struct BadFile {
  const char* what;
  const char* text;
  const char* expected;  // file:line:col: key path ...
};

TEST(WorldYamlTest, ABadWorldFileGivesOneLineNamingFileLineAndKey) {
  const BadFile cases[] = {
      {"unknown key", "name: t\nwalls:\n  - {type: box, center_m: [1, 1], sise_m: [1, 1]}\n",
       "bad.yaml:3:35: walls[0].sise_m: unknown key"},
      {"negative friction",
       "name: t\nzones:\n  - name: z\n    shape: {type: circle, radius_m: 1.0}\n    mu: -0.2\n",
       "bad.yaml:5:9: zones[0].mu = -0.2; must be >= 0"},
      {"self-intersecting polygon",
       "name: t\nwalls:\n  - type: polygon\n    points_m: [[0, 0], [2, 2], [2, 0], [0, 2]]\n",
       "bad.yaml:3:5: walls[0].points_m: edges 0 and 2 cross"},
      {"wrong type", "name: t\nfloor: {mu: slippery}\n",
       "bad.yaml:2:13: floor.mu: expected a number, got 'slippery'"},
      {"unknown shape", "name: t\nwalls:\n  - {type: blob}\n",
       "bad.yaml:3:12: walls[0].type: 'blob' is not one of: box, polygon, polyline, circle"},
      {"spawn inside a wall",
       "name: t\nspawn: {x_m: 1.0, y_m: 1.0}\nwalls:\n  - {type: circle, center_m: [1, 1]}\n",
       "bad.yaml:1:1: walls[0]: contains the spawn point (1, 1)"},
      {"missing map", "name: t\nmap: {yaml_path: no_such_map.yaml}\n",
       "bad.yaml:2:18: map.yaml_path: no such map file"},
  };
  for (const BadFile& c : cases) {
    const std::string path = WriteFile("bad.yaml", c.text);
    const std::string error = ErrorOf([&] { LoadWorldSpec(path); });
    EXPECT_THAT(error, HasSubstr(c.expected)) << c.what;
    EXPECT_THAT(error, HasSubstr(testing::TempDir())) << c.what;
    EXPECT_THAT(error, Not(HasSubstr("\n"))) << c.what;
  }
}

TEST(WorldYamlTest, AMissingMapImageNamesTheMapFileAndKey) {
  WriteFile("broken_map.yaml",
            "image: nowhere.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  const std::string path =
      WriteFile("bad_map_world.yaml", "name: t\nmap:\n  yaml_path: broken_map.yaml\n");
  const std::string error = ErrorOf([&] { LoadWorldSpec(path); });
  EXPECT_THAT(error, HasSubstr("bad_map_world.yaml:3:14: map.yaml_path: cannot load the map: "));
  EXPECT_THAT(error, HasSubstr("broken_map.yaml:1:8: image: map image"));
  EXPECT_THAT(error, HasSubstr("nowhere.pgm' does not exist"));
  EXPECT_THAT(error, Not(HasSubstr("\n")));
}

TEST(WorldYamlTest, ResolvedWorldReadsBackToTheSameYaml) {
  for (const char* name : {"office", "corridor", "two_rooms", "hall", "lab_map"}) {
    const WorldSpec spec = LoadWorldSpec(FindPresetFile(name, "worlds"));
    const std::string yaml = WorldSpecToYaml(spec);
    const std::string path = WriteFile(std::string(name) + "_resolved.yaml", yaml);
    EXPECT_EQ(WorldSpecToYaml(LoadWorldSpec(path)), yaml) << name;
  }
}

TEST(RobotYamlTest, ABadRobotFileGivesOneLineNamingFileLineAndKey) {
  const BadFile cases[] = {
      {"unknown key", "name: r\nlidar:\n  num_beems: 10\n",
       "bad_robot.yaml:3:3: lidar.num_beems: unknown key"},
      {"out of range", "name: r\nlidar:\n  num_beams: 0\n",
       "bad_robot.yaml:3:14: lidar.num_beams = 0; must be > 1"},
      {"negative torque", "name: r\nmotor: {max_torque_n_m: -1}\n",
       "bad_robot.yaml:2:25: motor.max_torque_n_m = -1; must be > 0"},
      {"wrong type", "name: r\nwheels:\n  per_side: two\n",
       "bad_robot.yaml:3:13: wheels.per_side: expected an integer, got 'two'"},
      {"nested imu", "name: r\nimu:\n  gyro: {scale_error: -2}\n",
       "bad_robot.yaml:3:23: imu.gyro.scale_error = -2; must be > -1"},
  };
  for (const BadFile& c : cases) {
    const std::string path = WriteFile("bad_robot.yaml", c.text);
    const std::string error = ErrorOf([&] { LoadRobotSpec(path); });
    EXPECT_THAT(error, HasSubstr(c.expected)) << c.what;
    EXPECT_THAT(error, Not(HasSubstr("\n"))) << c.what;
  }
}

TEST(RobotYamlTest, PresetsLoadAndReadBack) {
  for (const char* name : {"ece276a", "small_diff"}) {
    const RobotSpec spec = LoadRobotSpec(FindPresetFile(name, "robots"));
    EXPECT_EQ(spec.name, name);
    const std::string yaml = RobotSpecToYaml(spec);
    const std::string path = WriteFile(std::string(name) + "_resolved.yaml", yaml);
    EXPECT_EQ(RobotSpecToYaml(LoadRobotSpec(path)), yaml) << name;
  }
  const RobotSpec ece = LoadRobotSpec(FindPresetFile("ece276a", "robots"));
  EXPECT_EQ(ece.wheels.per_side, 2);
  EXPECT_EQ(ece.wheels.radius_m, 0.127);
  EXPECT_EQ(ece.encoders.ticks_per_revolution, 360);
  EXPECT_EQ(ece.lidar.num_beams, 1081);
  EXPECT_EQ(ErrorOf([] { FindPresetFile("no_such_robot", "robots"); }).substr(0, 40),
            "'no_such_robot': no such robot file (loo");
}

}  // namespace
}  // namespace slamrig::sim
