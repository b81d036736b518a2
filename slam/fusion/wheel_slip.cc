#include "slam/fusion/wheel_slip.h"

#include <algorithm>
#include <cmath>

namespace slamrig::slam {

WheelSlipDetector::WheelSlipDetector(double track_width_m, double resolution_m,
                                     double encoder_sigma_rel)
    : track_width_m_(track_width_m),
      resolution_m_(std::max(0.0, resolution_m)),
      encoder_sigma_rel_(std::max(0.0, encoder_sigma_rel)) {}

WheelSlipStep WheelSlipDetector::Add(double right_m, double left_m, double gyro_yaw_rad,
                                     double interval_s) {
  const double gyro_m = track_width_m_ * gyro_yaw_rad;
  const double residual = (right_m - left_m) - skid_ratio_ * gyro_m;
  const double fade = interval_s > 0.0 ? std::exp(-interval_s / kWindowS) : 1.0;
  window_m_ = window_m_ * fade + residual;
  gyro_window_m_ = gyro_window_m_ * fade + gyro_m;
  // The distance's modelled sigma is rel * (|right| + |left|) / 2; the difference gets twice it.
  const double wheel_noise = encoder_sigma_rel_ * (std::abs(right_m) + std::abs(left_m));
  noise_window_m2_ = noise_window_m2_ * fade * fade + wheel_noise * wheel_noise;
  // The ratio's error over the window, (residual / gyro differential), clipped to +-1 so that
  // a slip far off the ratio moves it no more than one a little off (a median's robustness: a
  // minority of turns on ice cannot pull it far), and proportional near it (a sign step would
  // cycle round it with the window's lag). A window whose turn is within quantisation says
  // nothing. A ratio below 1 would mean the wheels roll less than the base turns, which no slip
  // explains.
  if (std::abs(gyro_window_m_) > 2.0 * resolution_m_) {
    const double error = std::clamp(window_m_ / gyro_window_m_, -1.0, 1.0);
    skid_ratio_ = std::max(1.0, skid_ratio_ + kRatioStepPerRad * std::abs(gyro_yaw_rad) * error);
  }
  if (!(interval_s > 0.0)) return {};
  // In steady slip of v * interval per interval the window holds v * interval / (1 - fade), so
  // the window's excess times (1 - fade) is the slip of this interval, at any encoder rate.
  const double excess = std::max(
      0.0, std::abs(window_m_) - 2.0 * resolution_m_ - kNoiseGate * std::sqrt(noise_window_m2_));
  const double slip = excess * (1.0 - fade);
  total_slip_m_ += slip;
  const double before = slip_window_m_ * fade;
  slip_window_m_ = before + slip;
  return {slip, slip_window_m_ * slip_window_m_ - before * before};
}

}  // namespace slamrig::slam
