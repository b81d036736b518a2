#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "slam/types/records.h"

namespace slamrig::slam {

struct DiffDriveParams;  // slam/odometry/wheel_odometry.h

/// The mean of one side's wheel ticks (robots with several wheels per side); 0 for none.
double MeanTicks(const std::vector<std::int32_t>& ticks);

/// The encoder counts and gyro rates gathered over one interval (between two ticks records, or
/// two scans), reduced to the motion over it in one place for every integrator (WheelOdometry,
/// ScanSynchronizer): per side distance = the mean of its wheels' ticks * metres per tick, summed
/// over the interval's records; v from the mean of both sides; the yaw change from the mean gyro z
/// rate times the interval (the ECE276A reports' v from encoders, omega from the IMU), else from
/// the wheel difference (Wang, ECE276A report, Sec. III-A).
class OdometryInterval {
 public:
  /// Adds one tick-increment record; both sides need at least one wheel (checked).
  void AddTicks(const WheelTicks& ticks);
  /// Adds one gyro z rate, rad/s.
  void AddGyro(double rate_rad_s) {
    gyro_sum_rad_s_ += rate_rad_s;
    ++gyro_count_;
  }

  /// True once any tick record was added (Clear() keeps it: it says whether ticks ever came).
  bool has_ticks() const { return has_ticks_; }
  int gyro_samples() const { return gyro_count_; }

  /// The motion over the interval.
  struct Motion {
    double distance_m = 0.0;     ///< signed, v * tau
    double yaw_rad = 0.0;        ///< omega * tau
    bool gyro_fallback = false;  ///< `use_gyro`, but no gyro sample fell into the interval
  };
  /// The motion over `dt_s` seconds, then the interval starts empty. The yaw comes from the mean
  /// gyro rate when `use_gyro` and there are samples; else from `*held_rate` (the last interval's
  /// mean rate, for short dropouts) when given and set; else from the encoders. `*held_rate`, when
  /// given, is updated with this interval's mean rate.
  Motion Take(const DiffDriveParams& robot, double dt_s, bool use_gyro,
              std::optional<double>* held_rate);
  /// Forgets what was gathered.
  void Clear();

 private:
  double right_ticks_ = 0.0;
  double left_ticks_ = 0.0;
  double gyro_sum_rad_s_ = 0.0;
  int gyro_count_ = 0;
  bool has_ticks_ = false;
};

}  // namespace slamrig::slam
