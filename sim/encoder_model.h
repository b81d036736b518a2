#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "slam/types/random_stream.h"
#include "slam/types/records.h"

namespace slamrig::sim {

/// Incremental wheel encoders, sampled together. Defaults are the ECE276A robot's (360 ticks per
/// wheel revolution, 40 Hz).
struct EncoderOptions {
  bool enabled = true;             ///< false: the robot has no encoders
  double rate_hz = 40.0;           ///< samples per second
  int ticks_per_revolution = 360;  ///< ticks per wheel revolution
  /// Random slip: each wheel's counted rotation is (1 + s) times its turn, with
  /// s = s_common + s_wheel, s_common ~ N(0, slip_common_stddev^2) shared by all wheels and
  /// s_wheel ~ N(0, slip_stddev^2) each wheel's own (s clamped to +-0.5), held while the wheels
  /// travel slip_length_m on average and then drawn afresh: a patch of floor, a load shift.
  /// The shared part scales distance and turning alike (error per metre and per radian turned);
  /// the wheels' own parts differ between the sides and bend the heading (error per metre of
  /// about sqrt(2) slip_stddev / track width). Both 0: none, and no draws at all.
  double slip_stddev = 0.0;
  double slip_common_stddev = 0.0;
  double slip_length_m = 1.0;  ///< mean wheel travel (m) over which one set of draws holds

  /// One message per broken rule, e.g. "ticks_per_revolution = 0; must be > 0".
  std::vector<std::string> Validate() const;
};

/// Counts each wheel's own rotation in whole ticks (so slip, skid and a wrong radius all reach
/// the odometry exactly as on a real robot) and reports the increments since the last sample.
/// Each encoder starts at a random phase within one tick (stream "encoders"); the slip draws, if
/// any, come from the stream "encoders.slip".
class EncoderModel {
 public:
  /// `options` must be valid (checked); `num_right` and `num_left` wheels, front to back, of
  /// radius `wheel_radius_m` (> 0, checked; it turns slip_length_m into wheel rotation).
  EncoderModel(const EncoderOptions& options, int num_right, int num_left, std::uint64_t seed,
               double wheel_radius_m);

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
  // Slip (only when a slip stddev is > 0), per wheel: the counted rotation, the true angle of
  // the last sample and the slip fraction in force; the mean rotation the draws have held for.
  double slip_length_rad_ = 0.0;
  RandomStream slip_rng_;
  std::vector<double> counted_rad_, last_true_rad_, slip_;
  double slip_held_rad_ = 0.0;
  void DrawSlip();
};

}  // namespace slamrig::sim
