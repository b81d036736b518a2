#pragma once

// Field tables (slam/config/fields.h) of the matchers' options, for the algorithms that expose
// them in their configuration (icp-odometry, graph).

#include "slam/matching/correlative_matcher.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/icp_odometry.h"

namespace slamrig::slam {

/// The field table of IcpOptions.
template <typename V>
void VisitFields(V& v, IcpOptions& o) {
  v.Enum(
      "metric", o.metric,
      {{IcpMetric::kPointToLine, "point_to_line"}, {IcpMetric::kPointToPoint, "point_to_point"}});
  v("max_iterations", o.max_iterations);
  v("converged_translation_m", o.converged_translation_m);
  v("converged_rotation_rad", o.converged_rotation_rad);
  v("max_correspondence_distance_m", o.max_correspondence_distance_m);
  v("trim_fraction", o.trim_fraction);
  v.Enum("kernel", o.kernel,
         {{RobustKernel::kNone, "none"},
          {RobustKernel::kHuber, "huber"},
          {RobustKernel::kCauchy, "cauchy"}});
  v("kernel_scale_m", o.kernel_scale_m);
  v("normal_neighbors", o.normal_neighbors);
  v("normal_radius_m", o.normal_radius_m);
  v("min_correspondences", o.min_correspondences);
}

/// The field table of IcpOdometrySearchOptions.
template <typename V>
void VisitFields(V& v, IcpOdometrySearchOptions& o) {
  v("sigmas", o.sigmas);
  v("trigger_window_m", o.trigger_window_m);
  v("trigger_window_rad", o.trigger_window_rad);
  v("max_window_m", o.max_window_m);
  v("max_window_rad", o.max_window_rad);
  v("wide_window_m", o.wide_window_m);
  v("wide_window_rad", o.wide_window_rad);
  v("resolution_m", o.resolution_m);
  v("blur_m", o.blur_m);
  v("min_gain", o.min_gain);
  v("prior_weight", o.prior_weight);
  v("adapt_rate", o.adapt_rate);
  v("gap_s", o.gap_s);
  v("blind_scans", o.blind_scans);
}

/// The field table of IcpOdometryOptions.
template <typename V>
void VisitFields(V& v, IcpOdometryOptions& o) {
  v.Struct("icp", o.icp);
  v.Struct("points", o.points);
  v("local_map_keyframes", o.local_map_keyframes);
  v("local_map_voxel_m", o.local_map_voxel_m);
  v("keyframe_distance_m", o.keyframe_distance_m);
  v("keyframe_angle_rad", o.keyframe_angle_rad);
  v("max_translation_stddev_m", o.max_translation_stddev_m);
  v("max_covariance_ratio", o.max_covariance_ratio);
  v("max_yaw_stddev_rad", o.max_yaw_stddev_rad);
  v("weak_direction_ratio", o.weak_direction_ratio);
  v("weak_direction_gate_sigmas", o.weak_direction_gate_sigmas);
  v("min_score", o.min_score);
  v("max_correction_m", o.max_correction_m);
  v("max_correction_rad", o.max_correction_rad);
  v("sigma_xy_per_m", o.sigma_xy_per_m);
  v("sigma_xy_floor_m", o.sigma_xy_floor_m);
  v("sigma_yaw_per_rad", o.sigma_yaw_per_rad);
  v("sigma_yaw_per_m", o.sigma_yaw_per_m);
  v("sigma_yaw_floor_rad", o.sigma_yaw_floor_rad);
  v.Struct("search", o.search);
  v.Struct("calibration", o.calibration);
}

/// The field table of CorrelativeMatcherOptions (the windows of a loop search are set per
/// candidate; these are the defaults and caps).
template <typename V>
void VisitFields(V& v, CorrelativeMatcherOptions& o) {
  v("linear_window_m", o.linear_window_m);
  v("angular_window_rad", o.angular_window_rad);
  v("angular_step_rad", o.angular_step_rad);
  v("branch_and_bound_depth", o.branch_and_bound_depth);
  v("min_score", o.min_score);
  v("covariance_half_cells", o.covariance_half_cells);
  v("covariance_half_steps", o.covariance_half_steps);
  v("covariance_score_scale", o.covariance_score_scale);
}

}  // namespace slamrig::slam
