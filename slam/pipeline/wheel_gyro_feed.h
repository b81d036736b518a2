#pragma once

#include <cmath>
#include <optional>

#include "slam/fusion/pose_ekf_options.h"
#include "slam/fusion/wheel_slip.h"
#include "slam/odometry/odometry_interval.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// Feeds wheel ticks and gyro samples to a Kalman filter with PoseEkf's motion interface
/// (PoseEkf, EkfSlam) at their own rates: the gyro predicts the heading between tick intervals
/// (zero-order hold), the ticks predict the motion with the gyro's yaw since the last interval
/// when there was one, and a run of still intervals turns gyro samples into zero-rate updates of
/// the bias, and the wheels' differential against the gyro's yaw gives the slip the gyro sees
/// (WheelSlipDetector). `Filter` has gyro_bias(), gyro_bias_variance(), PredictGyro(rate, dt),
/// PredictWheels(right_m, left_m, track_m, optional gyro yaw, slip_m2) and UpdateZeroRate(rate).
template <typename Filter>
class WheelGyroFeed {
 public:
  /// `use_gyro` false (odometry.use_gyro) leaves the heading to the encoders.
  WheelGyroFeed(const DiffDriveParams& robot, bool use_gyro, const PoseEkfOptions& motion)
      : robot_(robot),
        use_gyro_(use_gyro),
        motion_(motion),
        slip_(robot.track_width_m, robot.MetresPerTick(), motion.encoder_sigma_rel) {}

  void AddImu(const ImuSample& imu, Filter& filter) {
    if (!use_gyro_) return;
    const double rate = imu.angular_velocity_rad_s.z();
    if (!std::isfinite(rate)) return;
    if (last_imu_time_) {
      const double dt = SecondsBetween(imu.time, *last_imu_time_);
      if (dt > 0.0) {
        gyro_yaw_since_ticks_ += (rate - filter.gyro_bias()) * dt;
        filter.PredictGyro(rate, dt);
        gyro_since_ticks_ = true;
      }
    }
    last_imu_time_ = imu.time;
    // Encoder ticks are coarse (a slow turn can leave an interval without a tick), so only a run
    // of still intervals counts, and a sample far from the bias (chi2_1 at 0.999) is no
    // standstill.
    if (still_intervals_ >= kStillIntervals && motion_.zero_rate_updates) {
      const double innovation = rate - filter.gyro_bias();
      const double variance =
          filter.gyro_bias_variance() + motion_.gyro_sigma_rad_s * motion_.gyro_sigma_rad_s;
      if (innovation * innovation < kZeroRateGate * variance) {
        filter.UpdateZeroRate(rate);
        ++zero_rate_updates_;
      }
    }
  }

  void AddTicks(const WheelTicks& ticks, Filter& filter) {
    const double metres_per_tick = robot_.MetresPerTick();
    const double right_m = MeanTicks(ticks.right_ticks) * metres_per_tick;
    const double left_m = MeanTicks(ticks.left_ticks) * metres_per_tick;
    // The interval's length for the slip's window (0 at the first ticks: no slip reported).
    const double interval_s =
        last_ticks_time_ ? SecondsBetween(ticks.time, *last_ticks_time_) : 0.0;
    last_ticks_time_ = ticks.time;
    const WheelSlipStep slip = gyro_since_ticks_
                                   ? slip_.Add(right_m, left_m, gyro_yaw_since_ticks_, interval_s)
                                   : WheelSlipStep{};
    filter.PredictWheels(
        right_m, left_m, robot_.track_width_m,
        gyro_since_ticks_ ? std::optional<double>(gyro_yaw_since_ticks_) : std::nullopt,
        slip.coherent_m2);
    still_intervals_ = right_m == 0.0 && left_m == 0.0 ? still_intervals_ + 1 : 0;
    saw_ticks_ = true;
    gyro_since_ticks_ = false;
    gyro_yaw_since_ticks_ = 0.0;
  }

  /// Whether any ticks came: without them the estimators predict from odometry-pose increments.
  bool saw_ticks() const { return saw_ticks_; }
  int zero_rate_updates() const { return zero_rate_updates_; }
  const WheelSlipDetector& slip() const { return slip_; }

 private:
  static constexpr int kStillIntervals = 10;
  static constexpr double kZeroRateGate = 10.83;

  DiffDriveParams robot_;
  bool use_gyro_ = true;
  PoseEkfOptions motion_;
  bool saw_ticks_ = false;
  int still_intervals_ = 0;  // consecutive encoder intervals without a tick
  std::optional<Time> last_imu_time_;
  bool gyro_since_ticks_ = false;
  double gyro_yaw_since_ticks_ = 0.0;
  int zero_rate_updates_ = 0;
  WheelSlipDetector slip_;
  std::optional<Time> last_ticks_time_;
};

}  // namespace slamrig::slam
