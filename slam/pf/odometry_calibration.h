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
  /// Off by default: on the ten corrected logs (seed 1) it halves intel's error but costs
  /// acapulco, belgioioso and fhw (see README, "Odometry self-calibration").
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

  /// One message per broken rule (prefixed "odometry_calibration.").
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
}

/// The running fit of OdometryCalibrationOptions. Deterministic, no state but two sums.
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

  /// The fitted heading drift, rad per metre travelled (counter-clockwise positive).
  double drift_rad_per_m() const;

 private:
  OdometryCalibrationOptions options_;
  double sum_error_rad_ = 0.0;  // exponentially forgotten sums over the observed updates
  double sum_distance_m_ = 0.0;
};

}  // namespace slamrig::slam
