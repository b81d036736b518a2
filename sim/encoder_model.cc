#include "sim/encoder_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "slam/types/check.h"
#include "slam/types/random_stream.h"
#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> EncoderOptions::Validate() const {
  Rules rules;
  rules.InRange("rate_hz", rate_hz, 0.0, 10000.0, Ends::kOpenLow)
      .Positive("ticks_per_revolution", ticks_per_revolution)
      .InRange("slip_stddev", slip_stddev, 0.0, 0.3)
      .InRange("slip_common_stddev", slip_common_stddev, 0.0, 0.3)
      .Positive("slip_length_m", slip_length_m);
  return rules.errors();
}

EncoderModel::EncoderModel(const EncoderOptions& options, int num_right, int num_left,
                           std::uint64_t seed, double wheel_radius_m)
    : options_(options), num_right_(num_right), slip_rng_(seed, "encoders.slip") {
  SLAMRIG_CHECK_VALID(options_, "EncoderOptions");
  SLAMRIG_CHECK(num_right > 0 && num_left > 0, "an encoder per side at least");
  SLAMRIG_CHECK(wheel_radius_m > 0.0, "wheel_radius_m > 0");
  RandomStream rng(seed, "encoders");
  for (int i = 0; i < num_right + num_left; ++i) phase_ticks_.push_back(rng.Uniform());
  // Counts at zero rotation, so the first sample reports what turned since the start.
  for (const double phase : phase_ticks_) {
    last_counts_.push_back(static_cast<std::int64_t>(std::floor(phase)));
  }
  if (options_.slip_stddev > 0.0 || options_.slip_common_stddev > 0.0) {
    slip_length_rad_ = options_.slip_length_m / wheel_radius_m;
    const std::size_t n = phase_ticks_.size();
    counted_rad_.assign(n, 0.0);
    last_true_rad_.assign(n, 0.0);
    slip_.assign(n, 0.0);
    DrawSlip();
  }
}

void EncoderModel::DrawSlip() {
  // Fixed order: the shared part, then each wheel's own.
  const double common = options_.slip_common_stddev * slip_rng_.Gaussian();
  for (double& s : slip_) {
    s = std::clamp(common + options_.slip_stddev * slip_rng_.Gaussian(), -0.5, 0.5);
  }
  slip_held_rad_ = 0.0;
}

WheelTicks EncoderModel::Measure(Time time, std::span<const double> wheel_angles_rad) {
  SLAMRIG_CHECK(wheel_angles_rad.size() == phase_ticks_.size(), "one angle per wheel");
  const double ticks_per_rad = options_.ticks_per_revolution / (2.0 * std::numbers::pi);
  WheelTicks ticks;
  ticks.time = time;
  double turned_rad = 0.0;  // summed over the wheels
  for (std::size_t i = 0; i < phase_ticks_.size(); ++i) {
    double counted_rad = wheel_angles_rad[i];
    if (!slip_.empty()) {
      // The turn since the last sample counts with the slip in force.
      const double turn = wheel_angles_rad[i] - last_true_rad_[i];
      last_true_rad_[i] = wheel_angles_rad[i];
      counted_rad_[i] += (1.0 + slip_[i]) * turn;
      turned_rad += std::abs(turn);
      counted_rad = counted_rad_[i];
    }
    const auto count =
        static_cast<std::int64_t>(std::floor(counted_rad * ticks_per_rad + phase_ticks_[i]));
    const auto increment = static_cast<std::int32_t>(count - last_counts_[i]);
    last_counts_[i] = count;
    (static_cast<int>(i) < num_right_ ? ticks.right_ticks : ticks.left_ticks).push_back(increment);
  }
  if (!slip_.empty()) {
    slip_held_rad_ += turned_rad / static_cast<double>(slip_.size());
    if (slip_held_rad_ >= slip_length_rad_) DrawSlip();
  }
  return ticks;
}

}  // namespace slamrig::sim
