#pragma once

#include <string>
#include <vector>

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// Online self-calibration of the odometry's heading drift (after Roy and Thrun, "Online
/// Self-Calibration for Mobile Robots", ICRA 1999: the systematic odometry error is estimated from
/// the corrections the localisation makes, and taken out of the next predictions). Wheels of
/// slightly different diameters turn the robot by a fixed amount per metre that the odometry does
/// not see: intel-corrected's odometry misses 0.057 rad/m, steady over the whole log, which the
/// scan matcher corrects only in part on new ground (the young map pulls the match towards the
/// prediction), so the first lap's map bends. The drift is fitted as rad per metre travelled,
/// from the heading the filter's estimate turned minus the heading the odometry turned between
/// updates, with an exponential memory in metres and a zero-drift prior.
struct OdometryCalibrationOptions {
  /// Off by default (README, "Odometry self-calibration"): at seed 1 it takes intel 0.171 ->
  /// 0.090 m and leaves six of the ten logs bit-identical, but intel seed 5 went 0.080 -> 0.107.
  bool enabled = false;
  /// Evidence from this many metres ago weighs 1/e: long enough to average the matcher's noise
  /// (~0.01 rad per update), short enough to follow a change of floor or load.
  double memory_m = 50.0;
  /// The fit is sum(error) / (sum(distance) + prior_m): as if prior_m metres without drift had
  /// been seen, so the first metres (and a log without drift) give a small correction.
  double prior_m = 5.0;
  /// An update whose heading correction exceeds this is no drift (a slip, a bad match, a switch
  /// of best particle between modes) and is left out of the fit.
  double max_error_rad = 0.15;
  /// The fitted drift is clamped to +-this (0.1 rad/m is a 5% difference of wheel diameters on a
  /// 0.5 m wheel base, far beyond a working robot).
  double max_drift_rad_per_m = 0.1;
  /// The drift is applied only when it stands this many standard errors clear of zero (the
  /// scatter of the updates' errors about the fit, over the remembered updates): a robot whose
  /// odometry does not drift keeps its predictions instead of following the matcher's noise.
  /// 0 = always applied.
  double min_significance = 3.0;

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of OdometryCalibrationOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, OdometryCalibrationOptions& o) {
  v("enabled", o.enabled);
  v("memory_m", o.memory_m);
  v("prior_m", o.prior_m);
  v("max_error_rad", o.max_error_rad);
  v("max_drift_rad_per_m", o.max_drift_rad_per_m);
  v("min_significance", o.min_significance);
}

/// The running fit of OdometryCalibrationOptions. Deterministic; its state is the forgotten sums
/// below.
class OdometryCalibration {
 public:
  explicit OdometryCalibration(const OdometryCalibrationOptions& options) : options_(options) {}

  /// The raw robot-frame increment with the fitted drift taken out: the extra rotation, drift x
  /// distance, spread half before and half after the translation (a constant turn rate along the
  /// step). The identity map when disabled or before any evidence.
  Pose2 Correct(const Pose2& raw_increment) const;

  /// One update's evidence: the raw odometry increment since the previous update and the
  /// estimate's increment over the same scans (previous estimate^-1 * current estimate).
  /// Returns false when the update was left out of the fit.
  bool Observe(const Pose2& raw_increment, const Pose2& estimated_increment);

  /// The fitted heading drift, rad per metre travelled (counter-clockwise positive), whether
  /// significant or not.
  double drift_rad_per_m() const;
  /// Its standard error from the scatter of the remembered updates (infinite before two).
  double standard_error_rad_per_m() const;
  /// The drift Correct() applies: drift_rad_per_m() when significant (min_significance), else 0.
  double applied_drift_rad_per_m() const;

 private:
  OdometryCalibrationOptions options_;
  double sum_error_rad_ = 0.0;  // exponentially forgotten sums over the observed updates
  double sum_distance_m_ = 0.0;
  double sum_error_sq_ = 0.0;  // for the scatter about the fit
  double sum_error_distance_ = 0.0;
  double sum_distance_sq_ = 0.0;
  double count_ = 0.0;          // sum of the weights
  double sum_weight_sq_ = 0.0;  // and of their squares
};

}  // namespace slamrig::slam
