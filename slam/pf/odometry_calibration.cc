#include "slam/pf/odometry_calibration.h"

#include <algorithm>
#include <cmath>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> OdometryCalibrationOptions::Validate() const {
  std::vector<std::string> errors;
  if (!(memory_m > 0.0)) errors.push_back(RuleViolation("memory_m", memory_m, "must be > 0"));
  if (!(prior_m > 0.0)) errors.push_back(RuleViolation("prior_m", prior_m, "must be > 0"));
  if (!(max_error_rad > 0.0)) {
    errors.push_back(RuleViolation("max_error_rad", max_error_rad, "must be > 0"));
  }
  if (!(max_drift_rad_per_m >= 0.0)) {
    errors.push_back(RuleViolation("max_drift_rad_per_m", max_drift_rad_per_m, "must be >= 0"));
  }
  return errors;
}

double OdometryCalibration::drift_rad_per_m() const {
  if (!options_.enabled) return 0.0;
  const double drift = sum_error_rad_ / (sum_distance_m_ + options_.prior_m);
  return std::clamp(drift, -options_.max_drift_rad_per_m, options_.max_drift_rad_per_m);
}

Pose2 OdometryCalibration::Correct(const Pose2& raw_increment) const {
  const double half = 0.5 * drift_rad_per_m() * raw_increment.translation().norm();
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
  return true;
}

}  // namespace slamrig::slam
