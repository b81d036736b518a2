#include "slam/odometry/odometry_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> OdometryCalibrationOptions::Validate() const {
  Rules rules;
  rules.Positive("memory_m", memory_m)
      .Positive("prior_m", prior_m)
      .Positive("max_error_rad", max_error_rad)
      .NonNegative("max_drift_rad_per_m", max_drift_rad_per_m)
      .NonNegative("min_significance", min_significance);
  return rules.errors();
}

double OdometryCalibration::drift_rad_per_m() const {
  if (!options_.enabled) return 0.0;
  const double drift = sum_error_rad_ / (sum_distance_m_ + options_.prior_m);
  return std::clamp(drift, -options_.max_drift_rad_per_m, options_.max_drift_rad_per_m);
}

double OdometryCalibration::standard_error_rad_per_m() const {
  if (!(count_ > 1.0)) return std::numeric_limits<double>::infinity();
  // e_i = a d_i + noise: the noise's variance is the weighted mean square of the residuals about
  // the fit a, and a = sum(w e) / (sum(w d) + prior) has the variance variance x sum(w^2) /
  // (sum(w d) + prior)^2 (the weights w are the forgetting's).
  const double a = sum_error_rad_ / (sum_distance_m_ + options_.prior_m);
  const double residual_sq =
      sum_error_sq_ - 2.0 * a * sum_error_distance_ + a * a * sum_distance_sq_;
  const double variance = std::max(residual_sq, 0.0) / count_;
  return std::sqrt(variance * sum_weight_sq_) / (sum_distance_m_ + options_.prior_m);
}

double OdometryCalibration::applied_drift_rad_per_m() const {
  const double drift = drift_rad_per_m();
  if (drift == 0.0) return 0.0;
  if (options_.min_significance == 0.0) return drift;
  return std::abs(drift) >= options_.min_significance * standard_error_rad_per_m() ? drift : 0.0;
}

Pose2 OdometryCalibration::Correct(const Pose2& raw_increment) const {
  const double half = 0.5 * applied_drift_rad_per_m() * raw_increment.translation().norm();
  if (half == 0.0) return raw_increment;
  return Pose2(0.0, 0.0, half) * raw_increment * Pose2(0.0, 0.0, half);
}

bool OdometryCalibration::Observe(const Pose2& raw_increment, const Pose2& estimated_increment) {
  if (!options_.enabled) return false;
  const double distance = raw_increment.translation().norm();
  const double error = NormalizeAngle(estimated_increment.theta() - raw_increment.theta());
  if (!(distance > 0.0) || !(std::abs(error) <= options_.max_error_rad)) return false;
  const double keep = std::exp(-distance / options_.memory_m);
  sum_error_rad_ = keep * sum_error_rad_ + error;
  sum_distance_m_ = keep * sum_distance_m_ + distance;
  sum_error_sq_ = keep * sum_error_sq_ + error * error;
  sum_error_distance_ = keep * sum_error_distance_ + error * distance;
  sum_distance_sq_ = keep * sum_distance_sq_ + distance * distance;
  count_ = keep * count_ + 1.0;
  sum_weight_sq_ = keep * keep * sum_weight_sq_ + 1.0;
  return true;
}

}  // namespace slamrig::slam
