#include "slam/pf/rbpf_options.h"

#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

template <typename T>
std::string Rule(const char* field, T value, const char* rule) {
  return RuleViolation(field, value, rule);
}

void NonNegative(const char* field, double value, std::vector<std::string>& errors) {
  if (!(value >= 0.0)) errors.push_back(Rule(field, value, "must be >= 0"));
}

void Positive(const char* field, double value, std::vector<std::string>& errors) {
  if (!(value > 0.0)) errors.push_back(Rule(field, value, "must be > 0"));
}

}  // namespace

std::vector<std::string> RbpfMotionNoise::Validate() const {
  std::vector<std::string> errors;
  NonNegative("xy_per_m", xy_per_m, errors);
  NonNegative("xy_per_rad", xy_per_rad, errors);
  NonNegative("yaw_per_m", yaw_per_m, errors);
  NonNegative("yaw_per_rad", yaw_per_rad, errors);
  // The floors keep the prior's Gaussian proper for a standing robot.
  Positive("min_xy_m", min_xy_m, errors);
  Positive("min_yaw_rad", min_yaw_rad, errors);
  return errors;
}

std::vector<std::string> RbpfOptions::Validate() const {
  std::vector<std::string> errors;
  if (num_particles <= 0) errors.push_back(Rule("particles", num_particles, "must be > 0"));
  AppendErrors(&errors, PrefixErrors("points", points.Validate()));
  AppendErrors(&errors, PrefixErrors("matcher", matcher.Validate()));
  AppendErrors(&errors, PrefixErrors("motion", motion.Validate()));
  Positive("proposal_xy_step_m", proposal_xy_step_m, errors);
  Positive("proposal_yaw_step_rad", proposal_yaw_step_rad, errors);
  if (!(proposal_spread >= 0.0 && proposal_spread <= 1.0)) {
    errors.push_back(Rule("proposal_spread", proposal_spread, "must be in [0, 1]"));
  }
  Positive("observation_scale", observation_scale, errors);
  if (!(weight_exponent > 0.0 && weight_exponent <= 1.0)) {
    errors.push_back(Rule("weight_exponent", weight_exponent, "must be in (0, 1]"));
  }
  NonNegative("weight_correlation_length_m", weight_correlation_length_m, errors);
  if (!(odometry_failure_probability >= 0.0 && odometry_failure_probability < 1.0)) {
    errors.push_back(
        Rule("odometry_failure_probability", odometry_failure_probability, "must be in [0, 1)"));
  }
  NonNegative("odometry_window_per_m", odometry_window_per_m, errors);
  Positive("odometry_window_min_m", odometry_window_min_m, errors);
  Positive("odometry_window_step_m", odometry_window_step_m, errors);
  if (!(odometry_degenerate_ratio >= 0.0 && odometry_degenerate_ratio < 1.0)) {
    errors.push_back(
        Rule("odometry_degenerate_ratio", odometry_degenerate_ratio, "must be in [0, 1)"));
  }
  if (!(resample_neff_ratio >= 0.0 && resample_neff_ratio <= 1.0)) {
    errors.push_back(Rule("resample_neff_ratio", resample_neff_ratio, "must be in [0, 1]"));
  }
  AppendErrors(&errors, PrefixErrors("map", map.Validate()));
  // The particles' tiled maps write every hit to its end cell (TiledGrid::InsertScan).
  if (map.range_stddev_m != 0.0) {
    errors.push_back(Rule("map.range_stddev_m", map.range_stddev_m, "must be 0 for the rbpf"));
  }
  NonNegative("min_update_distance_m", min_update_distance_m, errors);
  NonNegative("min_update_angle_rad", min_update_angle_rad, errors);
  if (num_threads < 1) errors.push_back(Rule("threads", num_threads, "must be >= 1"));
  return errors;
}

}  // namespace slamrig::slam
