#pragma once

#include <cstddef>
#include <functional>
#include <optional>

#include "slam/graph/pose_graph.h"
#include "slam/graph/pose_graph_optimizer.h"

namespace slamrig::slam {

/// What ReleaseWrongOdometryEdge did.
struct OdometryRelease {
  std::size_t edge = 0;      ///< index in graph.edges() of the released odometry edge
  int strained_before = 0;   ///< loop closures strained before it
  int strained_after = 0;    ///< and after
  PoseGraphSummary summary;  ///< of the solve that placed the graph after the release
};

/// Options of ReleaseWrongOdometryEdge.
struct OdometryReleaseOptions {
  /// The back end's solve (its robust loss on the loop closures).
  PoseGraphOptimizerOptions optimizer;
  /// The released edge keeps its measurement; its information is multiplied by this.
  double information_scale = 1e-4;
  /// Odometry edges tried, the most strained of the every-edge-robust solve first ...
  int max_candidates = 4;
  /// ... among those whose chi2 there is above this: a gross error (100: ten standard deviations
  /// of the edge's stated noise), a failed match, not noise of the kind the edge states. A
  /// front end's ordinary drift strains a few edges by 3 to 6 standard deviations.
  double min_candidate_chi2 = 100.0;
  /// A release is kept when it reconciles at least this many strained closures, and at least
  /// this share of them: one wrong edge explains most of the strain it causes, where a front end
  /// that drifted (many small errors, a corridor's) leaves strain that no single edge explains.
  int min_reconciled = 2;
  double min_reconciled_share = 0.5;
};

/// A front end's gross error (an alias one door along a corridor, a turn taken in a symmetric
/// room) is an odometry edge that is wrong by metres; every loop closure that spans it is then
/// strained, and a robust loss on the closures alone makes the wrong edge the cheaper explanation
/// (the closures are given up one by one, the error stays). With at least two loop closures
/// strained (chi2 above chi2_3's 99 % quantile) at the graph's current poses, this solves without a
/// robust loss and then with one on every edge (a gross error then concentrates on its own edge),
/// takes the odometry edges left above min_candidate_chi2 there as candidates, and for each
/// releases it and re-solves from that solve's poses with `options.optimizer`; the first release
/// that reconciles `min_reconciled` strained closures and `min_reconciled_share` of them, strains
/// no more of the other odometry edges than before, and is `plausible`, is kept, and `graph` holds
/// its solution. Several gross errors are released one call at a time. Otherwise
/// `graph` is left as it was and the answer is empty: one strained closure is never traded for an
/// edge. `eligible(k)` says whether edges()[k], an odometry edge, may be released, and
/// `plausible(k, relative)` whether the relative pose a release gives it (its `to` in its `from`'s
/// frame) is one the robot's own motion allows: closures that agree with each other (two identical
/// rooms taken for one) are explained as well by releasing the edge between them, which the
/// wheels rule out.
std::optional<OdometryRelease> ReleaseWrongOdometryEdge(
    PoseGraph* graph, const OdometryReleaseOptions& options,
    const std::function<bool(std::size_t)>& eligible,
    const std::function<bool(std::size_t, const Pose2&)>& plausible);

/// The loop-closure edges (kind kLoopClosure) whose chi2 at the graph's poses is above chi2_3's
/// 99 % quantile (11.34).
int CountStrainedClosures(const PoseGraph& graph);

}  // namespace slamrig::slam
