#pragma once

#include <string>
#include <vector>

#include "slam/graph/pose_graph_optimizer_options.h"
#include "slam/matching/correlative_matcher.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/icp_odometry.h"
#include "slam/matching/matching_fields.h"

namespace slamrig::slam {

/// How accepted loop closures are checked against each other.
enum class LoopConsistency {
  kNone,      ///< each closure on its own (its chi2 gate against the graph)
  kPairwise,  ///< and the largest pairwise-consistent set (pairwise_consistency.h)
};

/// The field table of PoseGraphOptimizerOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, PoseGraphOptimizerOptions& o) {
  v("max_iterations", o.max_iterations);
  v.Enum("trust_region", o.trust_region,
         {{TrustRegion::kLevenbergMarquardt, "levenberg_marquardt"},
          {TrustRegion::kDogleg, "dogleg"}});
  v("initial_trust_region_radius", o.initial_trust_region_radius);
  v.Enum("robust_loss", o.robust_loss,
         {{RobustLoss::kNone, "none"},
          {RobustLoss::kHuber, "huber"},
          {RobustLoss::kCauchy, "cauchy"},
          {RobustLoss::kSwitchable, "switchable"}});
  v("robust_loss_scale", o.robust_loss_scale);
  v("robust_loss_on_all_edges", o.robust_loss_on_all_edges);
  v("function_tolerance", o.function_tolerance);
  v("gradient_tolerance", o.gradient_tolerance);
  v("parameter_tolerance", o.parameter_tolerance);
}

/// Parameters of GraphSlam: the front end (ICP odometry, keyframes), the loop-closure search and
/// its verification, and the back end.
struct GraphSlamOptions {
  /// Scan-to-local-map ICP odometry between keyframes (its own keyframes build its local map).
  IcpOdometryOptions odometry;
  double keyframe_distance_m = 0.5;  ///< a scan becomes a graph node after moving this far ...
  double keyframe_angle_rad = 0.35;  ///< ... or turning this much since the last node
  /// Odometry edge noise between consecutive nodes (d: distance, |turn|: heading change):
  /// sigma_xy = edge_sigma_xy_per_m * d + edge_sigma_xy_floor_m, sigma_yaw =
  /// edge_sigma_yaw_per_rad * |turn| + edge_sigma_yaw_per_m * d + edge_sigma_yaw_floor_rad. The
  /// information is its inverse (the floors keep it regular). The translation and turn terms
  /// are IcpOdometry's own increment noise model; heading drift per metre is ICP's, far below
  /// the wheels'.
  double edge_sigma_xy_per_m = 0.05;
  double edge_sigma_xy_floor_m = 0.005;
  double edge_sigma_yaw_per_rad = 0.05;
  double edge_sigma_yaw_per_m = 0.005;
  double edge_sigma_yaw_floor_rad = 0.002;
  /// An edge over which the front end went blind (a failed match, a scan without points: the
  /// wheels' increment stood in) takes at least the odometry's noise: IcpOdometry's increment
  /// model (odometry.sigma_*) times the noise it measured, so that a loop closure bends the
  /// graph there, not along the matched stretches (docs/studies/graph.md).
  bool blind_edge_odometry_noise = true;
  /// Odometry check: each new node's ICP-odometry pose is re-searched by the correlative matcher
  /// against the last odometry_check_nodes nodes' points (0: off), within +-window of it, and
  /// refined by loop_icp; the re-match replaces the edge when its blurred-raster score beats the
  /// ICP odometry pose's by odometry_check_min_gain (ICP's local minima: a turn between scans a
  /// metre apart locked onto the wrong wall).
  int odometry_check_nodes = 3;
  double odometry_check_window_m = 0.3;
  double odometry_check_window_rad = 0.35;
  double odometry_check_min_gain = 0.1;
  /// A re-match's distance from the previous node must stay within this chi-square confidence
  /// (1 dof) of the wheels' distance since it, in the front end's increment noise
  /// (IcpOdometryOptions::IncrementSigmas times the noise it measured), unless ICP odometry's own
  /// pose strayed farther: then as far as that. 1 = no such limit, as in a run without the
  /// robot's own odometry (its increments are scan matches themselves).
  double odometry_check_wheel_confidence = 0.999;
  /// When ICP odometry's match was doubtful (see node_below_match_score) or failed since the last
  /// node, and the best of those
  /// scores below odometry_check_wide_below (0: never), the search is
  /// widened to +-odometry_check_wide_window_m and every heading: a prior lost altogether (a gap
  /// in the wheel odometry while the robot turned) is beyond any local search.
  double odometry_check_wide_below = 0.3;
  double odometry_check_wide_window_m = 1.0;
  /// The widened search's pose must score at least this itself (a scan that fits nothing well
  /// anywhere is not re-placed on the strength of a small gain).
  double odometry_check_wide_min_score = 0.5;
  /// A scan whose ICP odometry match (full or degenerate) scored below this becomes a
  /// node however little it moved, so that the odometry check judges it (0: only by motion).
  double node_below_match_score = 0.75;

  /// Loop closures are searched among nodes older than the last loop_skip_keyframes ...
  int loop_skip_keyframes = 30;
  /// ... within loop_search_radius_m + loop_radius_sigmas * sigma_xy (the position uncertainty
  /// accumulated along the graph's least uncertain path since that node), at most
  /// loop_max_search_radius_m ...
  double loop_search_radius_m = 1.0;
  double loop_radius_sigmas = 3.0;
  double loop_max_search_radius_m = 6.0;
  int loop_max_candidates = 1;  ///< ... the nearest few per new node
  /// Submap of a candidate: the scans of the nodes within +-this many of it, rastered ...
  int submap_half_keyframes = 5;
  double submap_resolution_m = 0.1;  ///< ... at this resolution, each point blurred by ...
  double submap_blur_m = 0.1;        ///< ... a Gaussian of this standard deviation
  /// The current side: this many last nodes' points in the current node's frame.
  int query_keyframes = 3;
  /// Correlative search (windows per candidate from the uncertainty, capped by these).
  CorrelativeMatcherOptions correlative = {.linear_window_m = 6.0,
                                           .angular_window_rad = 0.8,
                                           .branch_and_bound_depth = 6,
                                           .min_score = 0.55};
  /// ICP refinement of the correlative pose against the submap's points.
  IcpOptions loop_icp = {
      .max_correspondence_distance_m = 0.3, .trim_fraction = 0.9, .kernel = RobustKernel::kCauchy};
  double loop_min_icp_score = 0.7;     ///< inlier share of the refined match
  double loop_max_refinement_m = 0.3;  ///< ICP may move the correlative pose at most this far
  /// Ambiguity: the correlative score's spread (Olson's covariance) along its worst direction
  /// must stay below this standard deviation (a corridor slides along its axis) ...
  double loop_max_search_stddev_m = 0.15;
  /// ... and ICP's covariance may not be more elongated than this eigenvalue ratio.
  double loop_max_covariance_ratio = 100.0;
  /// Geometric verification: the closure's Mahalanobis distance to the graph's own relative pose
  /// (with the accumulated and the match covariance) must be below this chi2 (3 dof; 99.9 %).
  double loop_chi2_gate = 16.27;
  /// Pairwise consistency (Mangelson et al. 2018): with kPairwise (the default) the closures that
  /// pass the checks above enter the graph only while they belong to the largest set whose every
  /// pair closes its cycle through the odometry within loop_pairwise_chi2 (3 dof): an aisle's
  /// alias one rack over passes its own gate but not beside the true closures around it.
  LoopConsistency loop_consistency = LoopConsistency::kPairwise;
  double loop_pairwise_chi2 = 16.27;
  /// After the final optimisation, take out the closure the optimum leaves most strained (its
  /// chi2 above chi2_3's 99 % quantile, 11.34: the rest of the graph contradicts it) and
  /// re-optimise, while one is. A single wrong closure has no other closure to disagree with
  /// (pairwise consistency needs two): a corridor's start corner, seen half from the start,
  /// matched from the other side.
  bool loop_drop_strained = true;
  /// Before each closure is dropped (with loop_drop_strained): a front-end edge that is grossly
  /// wrong (an alias one door along a corridor, a turn taken the wrong way) strains every closure
  /// that spans it, and the robust loss on the closures alone makes the wrong edge the cheaper
  /// explanation: the closures are given up one by one and the error stays. While two or more
  /// closures are strained, an odometry edge that a solve with the robust loss on every edge
  /// leaves more than ten standard deviations off is released (its information times
  /// released_edge_information_scale, its measurement kept) when that reconciles at least two of
  /// the strained closures and at least half of them, strains no other odometry edge, and keeps
  /// the edge's distance within odometry_check_wheel_confidence of the wheels' (as the odometry
  /// check's re-match does; slam/graph/odometry_release.h). A single strained closure is never
  /// traded for an edge: it is dropped. Counted as released_odometry.
  bool release_wrong_odometry = true;
  double released_edge_information_scale = 1e-4;
  /// The loop edge's covariance: ICP's, raised to at least these standard deviations.
  double loop_sigma_xy_floor_m = 0.02;
  double loop_sigma_yaw_floor_rad = 0.005;
  /// Optimise when a closure was accepted and this many nodes were added since the last run.
  int optimize_every_keyframes = 10;
  /// Self-diagnosis after the final optimisation: an edge is strained when its chi2 exceeds the
  /// 99 % quantile of chi2 with 3 dof (11.34); the estimate is judged diverged when more than
  /// this share of the edges kept in the graph are strained (a consistent graph has about 1 %,
  /// fewer with the conservative default noise model; a front end that drifted and then closed a
  /// loop strains every edge between).
  double diverged_strained_share = 0.05;
  /// The back end; Cauchy on loop closures only, by default.
  PoseGraphOptimizerOptions optimizer = {
      .max_iterations = 50, .robust_loss = RobustLoss::kCauchy, .robust_loss_scale = 1.0};
  /// Threads: with two or more, the back end (placing a node, its loop search, the
  /// optimisations) runs on a thread of its own beside the front end's next scan; 1 runs both on
  /// the caller's. 0: one per processor this process may use, or SLAMRIG_THREADS
  /// (DefaultThreadCount). Results never depend on it.
  int num_threads = 0;

  /// One message per broken rule, named by the field table's keys.
  std::vector<std::string> Validate() const;
};

/// The field table of GraphSlamOptions.
template <typename V>
void VisitFields(V& v, GraphSlamOptions& o) {
  v.Struct("odometry_icp", o.odometry);
  v("keyframe_distance_m", o.keyframe_distance_m);
  v("keyframe_angle_rad", o.keyframe_angle_rad);
  v("edge_sigma_xy_per_m", o.edge_sigma_xy_per_m);
  v("edge_sigma_xy_floor_m", o.edge_sigma_xy_floor_m);
  v("edge_sigma_yaw_per_rad", o.edge_sigma_yaw_per_rad);
  v("edge_sigma_yaw_per_m", o.edge_sigma_yaw_per_m);
  v("edge_sigma_yaw_floor_rad", o.edge_sigma_yaw_floor_rad);
  v("blind_edge_odometry_noise", o.blind_edge_odometry_noise);
  v("odometry_check_nodes", o.odometry_check_nodes);
  v("odometry_check_window_m", o.odometry_check_window_m);
  v("odometry_check_window_rad", o.odometry_check_window_rad);
  v("odometry_check_min_gain", o.odometry_check_min_gain);
  v("odometry_check_wheel_confidence", o.odometry_check_wheel_confidence);
  v("odometry_check_wide_below", o.odometry_check_wide_below);
  v("odometry_check_wide_window_m", o.odometry_check_wide_window_m);
  v("odometry_check_wide_min_score", o.odometry_check_wide_min_score);
  v("node_below_match_score", o.node_below_match_score);
  v("loop_skip_keyframes", o.loop_skip_keyframes);
  v("loop_search_radius_m", o.loop_search_radius_m);
  v("loop_radius_sigmas", o.loop_radius_sigmas);
  v("loop_max_search_radius_m", o.loop_max_search_radius_m);
  v("loop_max_candidates", o.loop_max_candidates);
  v("submap_half_keyframes", o.submap_half_keyframes);
  v("submap_resolution_m", o.submap_resolution_m);
  v("submap_blur_m", o.submap_blur_m);
  v("query_keyframes", o.query_keyframes);
  v.Struct("correlative", o.correlative);
  v.Struct("loop_icp", o.loop_icp);
  v("loop_min_icp_score", o.loop_min_icp_score);
  v("loop_max_refinement_m", o.loop_max_refinement_m);
  v("loop_max_search_stddev_m", o.loop_max_search_stddev_m);
  v("loop_max_covariance_ratio", o.loop_max_covariance_ratio);
  v("loop_chi2_gate", o.loop_chi2_gate);
  v.Enum("loop_consistency", o.loop_consistency,
         {{LoopConsistency::kNone, "none"}, {LoopConsistency::kPairwise, "pairwise"}});
  v("loop_pairwise_chi2", o.loop_pairwise_chi2);
  v("loop_drop_strained", o.loop_drop_strained);
  v("release_wrong_odometry", o.release_wrong_odometry);
  v("released_edge_information_scale", o.released_edge_information_scale);
  v("loop_sigma_xy_floor_m", o.loop_sigma_xy_floor_m);
  v("loop_sigma_yaw_floor_rad", o.loop_sigma_yaw_floor_rad);
  v("optimize_every_keyframes", o.optimize_every_keyframes);
  v("diverged_strained_share", o.diverged_strained_share);
  v.Struct("optimizer", o.optimizer);
  v("threads", o.num_threads);
}

}  // namespace slamrig::slam
