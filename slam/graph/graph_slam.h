#pragma once

// Graph SLAM with verified loop closures: a keyframe pose graph (Lu and Milios, "Globally
// consistent range scan alignment for environment mapping", 1997; Grisetti et al., "A Tutorial on
// Graph-Based SLAM", 2010, Sec. III) whose odometry edges come from scan-to-local-map ICP
// (Censi 2008) and whose loop closures are found by correlative matching against a submap
// (Olson 2009; Hess et al. 2016, Sec. V), refined by ICP and accepted only when they agree with
// the graph within a chi2 gate on the accumulated uncertainty (the Mahalanobis test of
// Neira and Tardos, "Data association in stochastic mapping using the joint compatibility
// test", 2001, eq. 6, for a single pairing). Optimised with Ceres (g2o's error, eq. 1-2 of
// Kümmerle et al. 2011) and a robust loss on loop closures.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "slam/graph/graph_slam_options.h"
#include "slam/graph/pairwise_consistency.h"
#include "slam/graph/pose_graph.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "slam/matching/icp_odometry.h"
#include "slam/types/loop_closure.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"
#include "slam/types/thread_pool.h"

namespace slamrig::slam {

/// Counts of what GraphSlam did.
struct GraphSlamCounts {
  int keyframes = 0;
  int loop_candidates = 0;  ///< candidate pairs matched
  int loop_closures = 0;    ///< accepted
  int rejected = 0;         ///< candidates that failed a match or a check
  int optimizations = 0;
  double final_chi2 = 0.0;  ///< chi2 of the last optimisation
  /// Accepted closures whose switch the last optimisation turned off (below 0.5), with the
  /// switchable robust loss; they no longer count as loop closures.
  int switched_off = 0;
  int odometry_rematched = 0;  ///< odometry edges the odometry check replaced
  /// Loop candidates whose correlative match lay in the search window's outermost ring (no peak
  /// within the graph's uncertainty), rejected.
  int window_edge_rejected = 0;
  /// Loop candidates whose match passed every check of its own and failed only the chi-square
  /// gate against the graph: the scans fit there, the graph says elsewhere.
  int gate_rejected = 0;
  /// With pairwise consistency: closures that passed their own checks but are outside the
  /// largest pairwise-consistent set (so not in the graph).
  int inconsistent = 0;
  /// At Finish(): accepted closures taken out because the final optimum left them strained (their
  /// chi2 above chi2_3's 99 % quantile): the rest of the graph, every other closure included,
  /// contradicts them; they no longer count as loop closures.
  int dropped_strained = 0;
  /// At Finish(), before any closure is dropped: odometry edges (the front end's) released
  /// because, wrong, each explained two or more strained closures at once; their information is
  /// scaled down by released_edge_information_scale, so the closures place the nodes on each
  /// side. Each is a front-end failure the back end repaired.
  int released_odometry = 0;
  /// After Finish(): whether the final graph's solution is certified globally optimal
  /// (optimality_certificate.h) for the graph with every robust edge weighted by its final
  /// robust-loss weight, and the certificate matrix's smallest eigenvalue (NaN before Finish()
  /// or when it could not be computed).
  bool certified = false;
  double certificate_lambda_min = std::numeric_limits<double>::quiet_NaN();
  /// After Finish(): edges kept in the graph whose chi2 at the final poses exceeds chi2_3's 99 %
  /// quantile, and the estimator's own verdict from them (options' diverged_strained_share):
  /// the graph contradicts its own measurements, so the estimate is not to be trusted.
  int strained_edges = 0;
  /// After Finish(): the kept edges' chi2 at the final poses over the 99 % quantile of chi2 with
  /// their degrees of freedom (3 per edge less 3 per free node): above 1 the measurements
  /// contradict each other beyond their stated noise (NaN without redundant edges).
  double chi2_ratio = std::numeric_limits<double>::quiet_NaN();
  bool diverged = false;
};

/// Online graph SLAM over laser scans with an odometry increment each. Deterministic; not
/// thread-safe.
class GraphSlam {
 public:
  /// SLAMRIG_CHECKs that options.Validate() is empty.
  explicit GraphSlam(const GraphSlamOptions& options);
  /// Waits for the back end's work in hand.
  ~GraphSlam();
  GraphSlam(const GraphSlam&) = delete;
  GraphSlam& operator=(const GraphSlam&) = delete;

  /// Adds one scan taken after `odometry_increment` (previous base to this base, wheel odometry)
  /// and returns its online pose in the graph's frame (the first scan's base frame): the front
  /// end's motion since the newest node, placed where the graph has that node. A scan that
  /// becomes a node is placed by the back end after Add returns (with options.num_threads > 1
  /// on its own thread, beside the front end's next scan); every accessor below waits for it,
  /// and the next scan's pose is placed on it. Same results with any thread count.
  /// `odometry_gap_s`: how long the odometry was silent before the scan (IcpOdometry's search).
  Pose2 Add(const LaserScan& scan, const Pose2& odometry_increment, double odometry_gap_s = 0.0);
  /// Final optimisation.
  void Finish();

  /// The current estimate of every scan so far: its node's pose composed with the scan's pose
  /// relative to that node.
  std::vector<Pose2> Poses() const;
  /// The accepted loop closures the back end keeps (all of them, or with switchable constraints
  /// those whose switch is on).
  std::vector<LoopClosure> loop_closures() const;
  /// After Finish(): the accepted loop closures the final poses agree with: kept by the back end
  /// and not strained (JudgeConsistency). A front-end loss that one of them spans is repaired.
  std::vector<LoopClosure> UnstrainedLoopClosures() const;
  /// The candidates that failed their match or a check, each with the graph's relative pose
  /// between the two scans when it was tried.
  const std::vector<LoopClosure>& rejected_closures() const {
    JoinBackEnd();
    return rejected_;
  }
  const GraphSlamCounts& counts() const {
    JoinBackEnd();
    return counts_;
  }
  /// The scan-to-local-map front end (its measured odometry noise, noise_scale()).
  const IcpOdometry& front_end() const { return odometry_; }
  const PoseGraph& graph() const {
    JoinBackEnd();
    return graph_;
  }
  /// How the front end (ICP odometry) placed the last scan given to Add(), for its health.
  const IcpOdometryStep& last_step() const { return last_step_; }
  /// Whether the last scan given to Add() became a node of the graph.
  bool last_scan_is_node() const { return last_scan_is_node_; }

 private:
  // The wheels' motion between two nodes and its noise (sigma xy, sigma yaw), for the odometry
  // check: a re-match may not stray from it further than ICP odometry's own pose did.
  struct WheelMotion {
    Pose2 relative;
    Eigen::Vector2d sigmas{0, 0};
  };
  struct Node {
    int scan = 0;                         // index of its scan
    Pose2 odom_pose;                      // IcpOdometry's pose
    std::vector<Eigen::Vector2d> points;  // base frame
    Eigen::Vector2d edge_variance{0, 0};  // (xy, yaw) variance of the edge from the previous
    // checked^-1 * ICP relative of the edge from the previous node: the identity unless the
    // odometry check re-placed it, when it carries the next edge over from the previous node.
    Pose2 rematch_offset;
    WheelMotion wheels;  // since the previous node
  };
  // Whether `relative`'s distance from the previous node, signed (forwards or backwards in its
  // frame), stays within odometry_check_wheel_confidence (1 dof, the wheels' sigma) of the
  // wheels', or no farther from it than the front end's own `front_end` relative pose: a re-match
  // or a release may not contradict the wheels more than the front end did. Always true at
  // confidence 1 (no wheels of the robot's own).
  bool WheelsAllow(const WheelMotion& wheels, const Pose2& front_end, const Pose2& relative) const;
  // Waits until the back end has placed every node decided so far; rethrows what it threw.
  void JoinBackEnd() const;
  // Variances (xy, yaw) along the least uncertain graph path from the newest node to every node.
  std::vector<Eigen::Vector2d> PathVariances() const;
  void AddNode(int scan, const Pose2& odom_pose, bool doubtful,
               const std::optional<Eigen::Vector2d>& blind_noise, const WheelMotion& wheels,
               std::vector<Eigen::Vector2d> points);
  // The pose of `points` in the newest node's frame: `relative` (ICP odometry's), or the
  // odometry check's re-match when it fits the last nodes clearly better (from the better fitting
  // of `relative` and `alternative`, a local search, and
  // over every heading when ICP odometry's match was `doubtful` and the best so far fits poorly),
  // never one farther from the wheels' motion (in their sigmas) than `relative` or the gate.
  Pose2 CheckedRelative(const Pose2& relative, const Pose2& alternative, bool doubtful,
                        const WheelMotion& wheels, const std::vector<Eigen::Vector2d>& points);
  void SearchLoops();
  std::optional<PoseGraphEdge> TryClosure(int candidate, const Eigen::Vector2d& variance);
  // Adds an accepted closure to the graph, or with pairwise consistency to the hypotheses,
  // rebuilding the graph's closures when the consistent set changes.
  void AcceptClosure(const PoseGraphEdge& edge, const LoopClosure& closure);
  void AddClosureEdge(const PoseGraphEdge& edge, const LoopClosure& closure);
  void Optimize();
  // The optimality certificate of the current solution, into counts_.
  void CheckOptimality();
  // The strained edges and the diverged verdict at the current poses, into counts_.
  void JudgeConsistency();
  // Takes out, one at a time and re-optimising after each, the closure the optimum leaves most
  // strained, while one is.
  void DropStrainedClosures();
  // Releases an odometry edge that, wrong, strains two or more closures (odometry_release.h),
  // each edge at most once; true when it did.
  bool ReleaseWrongOdometryEdge();
  // Takes closure `i` (of closures_) out of the graph.
  void RemoveClosure(std::size_t i);
  // Rebuilds the graph with its vertices (at their current estimates) and the edges `keep`
  // accepts (by index), their variances with them; the switches are forgotten.
  void KeepEdges(const std::function<bool(std::size_t)>& keep);
  // Whether the last optimisation switched edge `e` off (below 0.5).
  bool SwitchedOff(std::size_t e) const;

  GraphSlamOptions options_;
  IcpOdometry odometry_;
  PoseGraph graph_;
  PoseGraphOptimizer optimizer_;
  std::vector<Node> nodes_;
  std::vector<int> scan_node_;                   // node of each scan
  std::vector<Pose2> scan_from_node_;            // each scan in its node's frame
  std::vector<Eigen::Vector2d> edge_variances_;  // (xy, yaw) of each graph edge, in order
  std::vector<LoopClosure> closures_;
  std::vector<LoopClosure> rejected_;
  std::vector<std::size_t> closure_edges_;  // graph edge of each closure
  std::vector<double> switches_;            // of each graph edge, from the last optimisation
  std::vector<bool> strained_;              // of each graph edge, after Finish()
  std::set<int> released_;                  // the `to` node of each released odometry edge
  GraphSlamCounts counts_;
  IcpOdometryStep last_step_;
  OdometryChain chain_;  // the odometry edges alone, for pairwise consistency
  PairwiseConsistency consistency_;
  std::vector<PoseGraphEdge> hypothesis_edges_;  // every closure given to consistency_
  std::vector<LoopClosure> hypothesis_closures_;
  bool pending_closure_ = false;
  int nodes_at_last_optimization_ = 0;

  // The front end's side, on the caller's thread only.
  bool failed_since_node_ = false;  // an ICP odometry match failed since the newest node
  bool blind_since_node_ = false;   // ... or a scan had no points (the odometry stood in)
  int nodes_decided_ = 0;           // nodes made, placed by the back end or still to be
  Pose2 newest_node_odom_pose_;     // the newest node's IcpOdometry pose
  Pose2 wheels_since_node_;  // the wheels' (calibrated) increments since the newest node, composed
  bool last_scan_is_node_ = false;
  // The back end's thread, when it has one (destroyed first: it waits for the task in hand).
  mutable BackgroundWorker back_end_;
};

}  // namespace slamrig::slam
