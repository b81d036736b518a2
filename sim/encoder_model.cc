#include "sim/encoder_model.h"

#include <cmath>
#include <numbers>

#include "slam/types/check.h"
#include "slam/types/random_stream.h"
#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> EncoderOptions::Validate() const {
  Rules rules;
  rules.InRange("rate_hz", rate_hz, 0.0, 10000.0, Ends::kOpenLow)
      .Positive("ticks_per_revolution", ticks_per_revolution);
  return rules.errors();
}

EncoderModel::EncoderModel(const EncoderOptions& options, int num_right, int num_left,
                           std::uint64_t seed)
    : options_(options), num_right_(num_right) {
  SLAMRIG_CHECK_VALID(options_, "EncoderOptions");
  SLAMRIG_CHECK(num_right > 0 && num_left > 0, "an encoder per side at least");
  RandomStream rng(seed, "encoders");
  for (int i = 0; i < num_right + num_left; ++i) phase_ticks_.push_back(rng.Uniform());
  // Counts at zero rotation, so the first sample reports what turned since the start.
  for (const double phase : phase_ticks_) {
    last_counts_.push_back(static_cast<std::int64_t>(std::floor(phase)));
  }
}

WheelTicks EncoderModel::Measure(Time time, std::span<const double> wheel_angles_rad) {
  SLAMRIG_CHECK(wheel_angles_rad.size() == phase_ticks_.size(), "one angle per wheel");
  const double ticks_per_rad = options_.ticks_per_revolution / (2.0 * std::numbers::pi);
  WheelTicks ticks;
  ticks.time = time;
  for (std::size_t i = 0; i < phase_ticks_.size(); ++i) {
    const auto count = static_cast<std::int64_t>(
        std::floor(wheel_angles_rad[i] * ticks_per_rad + phase_ticks_[i]));
    const auto increment = static_cast<std::int32_t>(count - last_counts_[i]);
    last_counts_[i] = count;
    (static_cast<int>(i) < num_right_ ? ticks.right_ticks : ticks.left_ticks).push_back(increment);
  }
  return ticks;
}

}  // namespace slamrig::sim
