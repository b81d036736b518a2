#include "slam/graph/odometry_release.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "slam/graph/edge_error.h"

namespace slamrig::slam {
namespace {

// The edges of `kind` other than `except` whose chi2 is above chi2_3's 99 % quantile.
int CountStrained(const PoseGraph& graph, EdgeKind kind, std::size_t except) {
  int strained = 0;
  for (std::size_t k = 0; k < graph.edges().size(); ++k) {
    const PoseGraphEdge& edge = graph.edges()[k];
    strained += k != except && edge.kind == kind && EdgeChi2(graph, edge) > kEdgeChi2P99;
  }
  return strained;
}

}  // namespace

int CountStrainedClosures(const PoseGraph& graph) {
  return CountStrained(graph, EdgeKind::kLoopClosure, graph.edges().size());
}

std::optional<OdometryRelease> ReleaseWrongOdometryEdge(
    PoseGraph* graph, const OdometryReleaseOptions& options,
    const std::function<bool(std::size_t)>& eligible,
    const std::function<bool(std::size_t, const Pose2&)>& plausible) {
  const int strained_before = CountStrainedClosures(*graph);
  if (strained_before < std::max(options.min_reconciled, 1)) return std::nullopt;
  // From the graph's poses a robust loss keeps what it has (the closures given up), so the trial
  // first solves without one (every closure pulls, the error spreads over the edges between), then
  // with the robust loss on every edge, which gathers a gross error back onto its own edge.
  PoseGraphOptimizerOptions least_squares = options.optimizer;
  least_squares.robust_loss = RobustLoss::kNone;
  PoseGraphOptimizerOptions every_edge = options.optimizer;
  every_edge.robust_loss_on_all_edges = true;
  PoseGraph trial = *graph;
  PoseGraphOptimizer(least_squares).Optimize(&trial);
  PoseGraphOptimizer(every_edge).Optimize(&trial);
  std::vector<std::pair<double, std::size_t>> candidates;
  for (std::size_t k = 0; k < trial.edges().size(); ++k) {
    const PoseGraphEdge& edge = trial.edges()[k];
    if (edge.kind != EdgeKind::kOdometry || !eligible(k)) continue;
    const double chi2 = EdgeChi2(trial, edge);
    if (chi2 > options.min_candidate_chi2) candidates.emplace_back(chi2, k);
  }
  // Most strained first; ties by index, so the order never depends on the sort's stability.
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  const std::size_t tries =
      std::min(candidates.size(), static_cast<std::size_t>(std::max(options.max_candidates, 0)));
  const PoseGraphOptimizer optimizer(options.optimizer);
  for (std::size_t i = 0; i < tries; ++i) {
    const std::size_t k = candidates[i].second;
    PoseGraph released = trial;
    released.SetEdgeInformation(k, released.edges()[k].information * options.information_scale);
    OdometryRelease release;
    release.summary = optimizer.Optimize(&released);
    release.edge = k;
    release.strained_before = strained_before;
    release.strained_after = CountStrainedClosures(released);
    const int reconciled = release.strained_before - release.strained_after;
    const PoseGraphEdge& edge = released.edges()[k];
    // The strain must be gone, not moved onto another front-end edge (a solve that pulls two
    // identical rooms onto each other strains the edge between them).
    const bool moved = CountStrained(released, EdgeKind::kOdometry, k) >
                       CountStrained(*graph, EdgeKind::kOdometry, k);
    if (!moved && reconciled >= options.min_reconciled &&
        reconciled >= options.min_reconciled_share * release.strained_before &&
        plausible(k, released.pose(edge.from).Between(released.pose(edge.to)))) {
      *graph = std::move(released);
      return release;
    }
  }
  return std::nullopt;
}

}  // namespace slamrig::slam
