// The robot profiles in robots/: each loads, simulates a few seconds in the office, and its lidar
// has the beam count, field of view and range its file states.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/presets.h"
#include "sim/robot_yaml.h"
#include "sim/simulator.h"
#include "sim/world_yaml.h"

namespace slamrig::sim {
namespace {

struct Profile {
  const char* name;
  int beams;
  double fov_deg;
  double range_max_m;
  double rate_hz;
};

constexpr Profile kProfiles[] = {
    {"sick_lms200_1deg", 181, 180.0, 81.91, 5.0},   {"sick_lms200_05deg", 361, 180.0, 81.91, 5.0},
    {"hokuyo_urg04lx", 683, 239.765625, 5.6, 10.0}, {"rplidar_a1", 360, 359.0, 12.0, 5.5},
    {"ece276a", 1081, 270.0, 30.0, 40.0},           {"odom_calibrated", 181, 180.0, 81.91, 5.0},
    {"odom_poor", 181, 180.0, 81.91, 5.0},          {"odom_intel", 181, 180.0, 81.91, 5.0},
    {"odom_2x_intel", 181, 180.0, 81.91, 5.0},
};

class RobotProfileTest : public ::testing::TestWithParam<Profile> {};

TEST_P(RobotProfileTest, LoadsAndSimulatesWithItsLidar) {
  const Profile& p = GetParam();
  SimulatorOptions options;
  options.world = LoadWorldSpec(FindPresetFile("office", "worlds"));
  options.robot = LoadRobotSpec(FindPresetFile(p.name, "robots"));
  ASSERT_TRUE(options.Validate().empty());
  Simulator sim(options);
  int scans = 0, odometry = 0;
  while (sim.time().seconds() < 5.0) {
    for (const Record& r : sim.Step().records) {
      odometry += std::holds_alternative<WheelTicks>(r);
      const auto* s = std::get_if<LaserScan>(&r);
      if (s == nullptr) continue;
      ++scans;
      ASSERT_EQ(s->ranges_m.size(), static_cast<std::size_t>(p.beams));
      const double span = s->BeamAngle(s->ranges_m.size() - 1) - s->BeamAngle(0);
      EXPECT_NEAR(span * 180.0 / std::numbers::pi, p.fov_deg, 1e-4);
      EXPECT_NEAR(s->range_max_m, p.range_max_m, 1e-5);
      int hits = 0;
      for (std::size_t i = 0; i < s->ranges_m.size(); ++i) {
        EXPECT_LE(s->ranges_m[i], s->range_max_m);
        hits += s->IsHit(i);
      }
      EXPECT_GT(hits, p.beams / 10);  // the office's walls are in reach of every profile
    }
  }
  EXPECT_NEAR(scans, 5.0 * p.rate_hz, 1.0);
  EXPECT_GT(odometry, 10);
}

INSTANTIATE_TEST_SUITE_P(Robots, RobotProfileTest, ::testing::ValuesIn(kProfiles),
                         [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace slamrig::sim
