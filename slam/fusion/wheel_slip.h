// Wheel slip seen by the gyro. For a rigid base turning at yaw rate w, the ground under the right
// and left wheels moves at v +- w b / 2, so whatever the wheels' rims roll beyond that is slip:
// (right - left) - b * gyro_yaw = s_right - s_left, the differential slip, exactly. A skid-steered
// base slips differentially in every turn (its encoders read about twice the yaw), so the part
// that is news is the residual from the base's usual skid ratio k, (right - left) - k b gyro_yaw,
// with k tracked online. On a slippery floor that residual is large, and the common-mode slip
// that corrupts the travelled distance (which no sensor here sees directly) is of its size: the
// filter's position covariance can grow while the slip happens, not after a match finds it.
#pragma once

namespace slamrig::slam {

/// One encoder interval's slip.
struct WheelSlipStep {
  double slip_m = 0.0;  ///< the differential slip this interval, metres (>= 0)
  /// How much this interval grows the square of the slip in the window: (S + slip)^2 - S^2, S
  /// the slip of the window before it. A position error in proportion to the slip, coherent
  /// over the window and independent across windows, has this variance per unit share squared.
  double coherent_m2 = 0.0;
};

/// Tracks the skid ratio and turns encoder intervals into the slip not explained by it.
/// Deterministic; one per filter.
class WheelSlipDetector {
 public:
  /// `resolution_m` is one encoder tick's travel: the differential's quantisation;
  /// `encoder_sigma_rel` the encoder noise the filter already models on the distance (sigma =
  /// rel * distance per interval, PoseEkfOptions), which is no slip: the wheels' independent
  /// errors put twice that on their difference.
  WheelSlipDetector(double track_width_m, double resolution_m, double encoder_sigma_rel = 0.0);

  /// One encoder interval of `interval_s` seconds: the wheels rolled `right_m` and `left_m`, the
  /// gyro turned `gyro_yaw_rad` (bias-corrected). The slip is the residual summed over the last
  /// ~kWindowS seconds, less what two ticks of quantisation and kNoiseGate standard deviations
  /// of the modelled encoder noise can make of it, spread over the window's time.
  WheelSlipStep Add(double right_m, double left_m, double gyro_yaw_rad, double interval_s);

  /// (right - left) / (b gyro yaw) in the turns so far, tracked by steps of the window's ratio
  /// error clipped to +-1, each as long as the yaw turned (1 before any turn: a differential
  /// drive).
  double skid_ratio() const { return skid_ratio_; }
  /// The slip reported so far, metres.
  double total_slip_m() const { return total_slip_m_; }

  /// The residual's averaging window, s: long enough that the differential's quantisation (two
  /// ticks at most, whatever the encoder rate) is small against a slip of a few cm/s, short
  /// against the seconds a slip on a patch of ice lasts.
  static constexpr double kWindowS = 0.5;
  /// How far one radian turned moves the skid ratio per unit of its error (at most 1): a
  /// 90-degree turn learns it from a differential drive's 1 to a skid-steered base's 2.4.
  static constexpr double kRatioStepPerRad = 1.0;
  /// Standard deviations of the modelled encoder noise in the window that are taken for noise.
  static constexpr double kNoiseGate = 3.0;

 private:
  double track_width_m_;
  double resolution_m_;
  double encoder_sigma_rel_;
  double skid_ratio_ = 1.0;
  double window_m_ = 0.0;         // the leaky sum of residuals, metres
  double gyro_window_m_ = 0.0;    // the leaky sum of b * gyro yaw, metres
  double noise_window_m2_ = 0.0;  // the modelled encoder noise's variance in window_m_
  double slip_window_m_ = 0.0;    // the leaky sum of the slip reported
  double total_slip_m_ = 0.0;
};

}  // namespace slamrig::slam
