#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "slam/types/records.h"

namespace slamrig::sim {

/// Incremental wheel encoders, sampled together. Defaults are the ECE276A robot's (360 ticks per
/// wheel revolution, 40 Hz).
struct EncoderOptions {
  bool enabled = true;             ///< false: the robot has no encoders
  double rate_hz = 40.0;           ///< samples per second
  int ticks_per_revolution = 360;  ///< ticks per wheel revolution

  /// One message per broken rule, e.g. "ticks_per_revolution = 0; must be > 0".
  std::vector<std::string> Validate() const;
};

/// Counts each wheel's own rotation in whole ticks (so slip, skid and a wrong radius all reach
/// the odometry exactly as on a real robot) and reports the increments since the last sample.
/// Each encoder starts at a random phase within one tick (stream "encoders").
class EncoderModel {
 public:
  /// `options` must be valid (checked); `num_right` and `num_left` wheels, front to back.
  EncoderModel(const EncoderOptions& options, int num_right, int num_left, std::uint64_t seed);

  /// Tick increments at `time` for the wheels' true rotation angles (rad, unwrapped, right wheels
  /// front to back, then left wheels front to back). The first call reports increments since 0.
  WheelTicks Measure(Time time, std::span<const double> wheel_angles_rad);

  /// The options it was built with.
  const EncoderOptions& options() const { return options_; }

 private:
  EncoderOptions options_;
  int num_right_;
  std::vector<double> phase_ticks_;        // per wheel, in [0, 1)
  std::vector<std::int64_t> last_counts_;  // per wheel
};

}  // namespace slamrig::sim
