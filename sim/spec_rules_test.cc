// The converted Validate() bodies of the simulator's specs: each broken rule names its key, the
// value and the bound, numbers as written (no "0.100000").
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "sim/encoder_model.h"
#include "sim/imu_model.h"
#include "sim/lidar_model.h"
#include "sim/robot_spec.h"
#include "sim/simulator.h"
#include "sim/world_spec.h"
#include "slam/types/validation.h"

namespace slamrig::sim {
namespace {

using ::testing::ElementsAre;

TEST(SpecRulesTest, EncoderRatesTicksAndSlip) {
  EncoderOptions o;
  o.rate_hz = 0.0;
  o.ticks_per_revolution = 0;
  o.slip_stddev = 0.35;
  o.slip_length_m = 0.0;
  EXPECT_THAT(
      o.Validate(),
      ElementsAre("rate_hz = 0; must be in (0, 10000]", "ticks_per_revolution = 0; must be > 0",
                  "slip_stddev = 0.35; must be in [0, 0.3]", "slip_length_m = 0; must be > 0"));
  EXPECT_TRUE(EncoderOptions{}.Validate().empty());
}

TEST(SpecRulesTest, RobotNestsItsPartsUnderTheirKeys) {
  RobotSpec r;
  r.wheels.caster_load_fraction = 1.0;
  r.calibration.track_width_error = -0.5;
  r.imu.gyro.scale_error = -1.5;
  r.lidar.fov_deg = 360.0;
  r.lidar.p_short = 0.7;
  r.lidar.p_max = 0.4;
  EXPECT_THAT(r.Validate(),
              ElementsAre("wheels.caster_load_fraction = 1; must be in [0, 1)",
                          "calibration.track_width_error = -0.5; must be in (-0.5, 0.5)",
                          "imu.gyro.scale_error = -1.5; must be > -1",
                          "lidar.fov_deg = 360; must be in (0, 360)",
                          "lidar.p_short + p_max + p_random = 1.102; must be <= 1"));
  r = RobotSpec{};
  r.lidar.range_noise_fraction = 1.0000001;
  EXPECT_THAT(r.Validate(),
              ElementsAre("lidar.range_noise_fraction = 1.0000001; must be in [0, 1]"));
}

TEST(SpecRulesTest, SimulatorWorldAndDrive) {
  SimulatorOptions o;
  o.physics_rate_hz = 20.0;
  o.velocity_iterations = 0;
  o.world.floor.rolling_resistance = 1.0;
  o.world.drive.laps = 0;
  EXPECT_THAT(o.Validate(), ElementsAre("world.floor.rolling_resistance = 1; must be in [0, 1)",
                                        "world.drive.laps = 0; must be >= 1",
                                        "physics_rate_hz = 20; must be in [50, 10000]",
                                        "velocity_iterations = 0; must be >= 1"));
}

}  // namespace
}  // namespace slamrig::sim
