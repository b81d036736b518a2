#include "slam/pipeline/wheel_gyro_feed.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>

namespace slamrig::slam {
namespace {

// Records what the feed passes on: the slip's variance term summed, and the intervals.
struct RecordingFilter {
  double gyro_bias() const { return 0.0; }
  double gyro_bias_variance() const { return 1.0; }
  void PredictGyro(double, double) {}
  void PredictWheels(double, double, double, std::optional<double>, double slip_m2) {
    slip_m2_sum += slip_m2;
    ++intervals;
  }
  double UpdateZeroRate(double) { return 0.0; }
  double slip_m2_sum = 0.0;
  int intervals = 0;
};

// Six seconds straight at 0.5 m/s with 40 Hz ticks and a 100 Hz gyro reading no turn; with
// `spin_ticks_per_interval` extra right-wheel ticks (one wheel spinning on ice).
double SlipTerm(int spin_ticks_per_interval) {
  const DiffDriveParams robot;
  WheelGyroFeed<RecordingFilter> feed(robot, true, PoseEkfOptions{});
  RecordingFilter filter;
  const double metres_per_tick = robot.MetresPerTick();
  double travelled = 0.0;
  std::int64_t ticks_so_far = 0;
  for (int ms = 0; ms <= 6000; ms += 5) {
    const Time t{static_cast<std::int64_t>(ms) * 1'000'000};
    if (ms % 10 == 0) {
      ImuSample imu;
      imu.time = t;
      feed.AddImu(imu, filter);
    }
    if (ms % 25 == 0) {
      travelled += 0.5 * 0.025;
      const auto total = static_cast<std::int64_t>(travelled / metres_per_tick);
      const auto step = static_cast<std::int32_t>(total - ticks_so_far);
      ticks_so_far = total;
      WheelTicks ticks;
      ticks.time = t;
      ticks.right_ticks = {step + spin_ticks_per_interval, step + spin_ticks_per_interval};
      ticks.left_ticks = {step, step};
      feed.AddTicks(ticks, filter);
    }
  }
  EXPECT_EQ(filter.intervals, 241);
  return filter.slip_m2_sum;
}

// Wheels that agree with the gyro pass no slip to the filter; a spinning wheel does: in steady
// slip the window holds the slip of kWindowS less the dead zone (two ticks and 3 sigma of the
// modelled encoder noise), and the coherent term grows by 2 (that excess)^2 per window.
TEST(WheelGyroFeedTest, PassesTheSlipTheGyroSeesToTheFilter) {
  EXPECT_EQ(SlipTerm(0), 0.0);
  const DiffDriveParams robot;
  const double tick = robot.MetresPerTick();
  const double window = WheelSlipDetector::kWindowS;
  const double fade = std::exp(-0.025 / window);
  const double held = tick / (1.0 - fade);  // one tick per interval, summed by the window
  const double noise = PoseEkfOptions{}.encoder_sigma_rel * 2.0 * 0.5 * 0.025 /
                       std::sqrt(1.0 - fade * fade);  // both wheels' noise in the window
  const double excess = held - 2.0 * tick - WheelSlipDetector::kNoiseGate * noise;
  // Steady for the 6 s less the filling of the residual's window, of the slip's window and of
  // the dead zone's crossing, about a window each (the discrete filters give 0.0232 where this
  // gives 0.0235).
  const double expected = 2.0 * excess * excess * (6.0 - 3.0 * window) / window;
  EXPECT_NEAR(SlipTerm(1), expected, 0.05 * expected);
}

}  // namespace
}  // namespace slamrig::slam
