#include "slam/pf/rbpf_options.h"

#include "slam/types/validation.h"

namespace slamrig::slam {
std::vector<std::string> RbpfMotionNoise::Validate() const {
  Rules rules;
  rules.NonNegative("xy_per_m", xy_per_m)
      .NonNegative("xy_per_rad", xy_per_rad)
      .NonNegative("yaw_per_m", yaw_per_m)
      .NonNegative("yaw_per_rad", yaw_per_rad)
      // The floors keep the prior's Gaussian proper for a standing robot.
      .Positive("min_xy_m", min_xy_m)
      .Positive("min_yaw_rad", min_yaw_rad);
  return rules.errors();
}

std::vector<std::string> RbpfOptions::Validate() const {
  const auto below_one = [](double v) { return v >= 0.0 && v < 1.0; };
  Rules rules;
  rules.Positive("particles", num_particles)
      .Nested("points", points.Validate())
      .Nested("matcher", matcher.Validate())
      .Nested("motion", motion.Validate())
      .Positive("proposal_xy_step_m", proposal_xy_step_m)
      .Positive("proposal_yaw_step_rad", proposal_yaw_step_rad)
      .Fraction("proposal_spread", proposal_spread)
      .Positive("observation_scale", observation_scale)
      .InUnitInterval("weight_exponent", weight_exponent)
      .NonNegative("weight_correlation_length_m", weight_correlation_length_m)
      .Require(below_one(odometry_failure_probability), "odometry_failure_probability",
               odometry_failure_probability, "must be in [0, 1)")
      .NonNegative("odometry_window_per_m", odometry_window_per_m)
      .Positive("odometry_window_min_m", odometry_window_min_m)
      .Positive("odometry_window_step_m", odometry_window_step_m)
      .NonNegative("odometry_gap_s", odometry_gap_s)
      .NonNegative("odometry_gap_window_m", odometry_gap_window_m)
      .NonNegative("scan_matched_window_m", scan_matched_window_m)
      .Fraction("scan_matched_accept_ratio", scan_matched_accept_ratio)
      .NonNegative("scan_matched_win_margin", scan_matched_win_margin)
      .Require(below_one(odometry_degenerate_ratio), "odometry_degenerate_ratio",
               odometry_degenerate_ratio, "must be in [0, 1)")
      .NonNegative("map_check_window_m", map_check_window_m)
      .Fraction("resample_neff_ratio", resample_neff_ratio)
      .Nested("map", map.Validate())
      // The particles' tiled maps write every hit to its end cell (TiledGrid::InsertScan).
      .Require(map.range_stddev_m == 0.0, "map.range_stddev_m", map.range_stddev_m,
               "must be 0 for the rbpf")
      .NonNegative("min_update_distance_m", min_update_distance_m)
      .NonNegative("min_update_angle_rad", min_update_angle_rad)
      .InRange("threads", num_threads, 0, 1024);
  return rules.errors();
}

}  // namespace slamrig::slam
