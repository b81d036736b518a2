#include "slam/pipeline/graph_slam_estimator.h"

#include <algorithm>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> GraphSlamEstimatorOptions::Validate() const {
  Rules rules;
  rules.Nested("", graph.Validate()).Nested("map", map.Validate());
  return rules.errors();
}

namespace {

// Without the robot's own odometry the increments are scan matches: the odometry check has no
// wheels to hold a re-match to.
GraphSlamOptions GraphOptions(const GraphSlamEstimatorOptions& options,
                              const EstimatorContext& context) {
  GraphSlamOptions graph = options.graph;
  if (!context.own_odometry) graph.odometry_check_wheel_confidence = 1.0;
  return graph;
}

}  // namespace

GraphSlamEstimator::GraphSlamEstimator(const GraphSlamEstimatorOptions& options,
                                       const EstimatorContext& context)
    : options_(options), slam_(GraphOptions(options, context)), map_(options.map) {}

ScanEstimate GraphSlamEstimator::AddScan(const SyncedScan& scan) {
  const Pose2 pose = slam_.Add(scan.scan, scan.increment, scan.odometry_gap_s);
  // Only the graph's nodes enter the map: inserting every scan at the scan rate wears thin walls
  // away (grazing beams clear them) and over-weights the places where the robot stood still.
  if (slam_.last_scan_is_node()) {
    map_.InsertScan(scan.scan, pose);
    node_scans_.push_back(scan.scan);
  }
  ScanEstimate estimate;
  estimate.pose = pose;
  estimate.lost = front_end_health_.Judge(slam_.last_step(), &estimate.trace);
  health_.Add(*estimate.lost);
  return estimate;
}

void GraphSlamEstimator::Finish() {
  slam_.Finish();
  // The map from the nodes' optimised poses.
  map_ = OccupancyGrid(options_.map);
  const PoseGraph& graph = slam_.graph();
  for (std::size_t k = 0; k < node_scans_.size(); ++k) {
    map_.InsertScan(node_scans_[k], graph.pose(static_cast<int>(k)));
  }
}

EstimatorView GraphSlamEstimator::View() const {
  EstimatorView view;
  const PoseGraph& graph = slam_.graph();
  view.edges.reserve(graph.edges().size());
  for (const PoseGraphEdge& e : graph.edges()) {
    view.edges.push_back({graph.pose(e.from).translation(), graph.pose(e.to).translation(),
                          e.kind == EdgeKind::kLoopClosure});
  }
  return view;
}

int GraphSlamEstimator::UnrepairedLosses() const {
  const std::vector<LoopClosure> closures = slam_.UnstrainedLoopClosures();
  int unrepaired = 0;
  for (const auto& loss : health_.loss_scans()) {
    // A closure repairs the loss when it spans it: from a scan before it to one after it.
    unrepaired += std::none_of(closures.begin(), closures.end(), [&](const LoopClosure& c) {
      return c.from_scan < loss.first && c.to_scan > loss.second;
    });
  }
  return unrepaired;
}

const std::vector<std::string>& GraphSlamEstimator::StatisticNames() {
  static const std::vector<std::string> names = {"keyframes",
                                                 "loop_closures",
                                                 "loop_candidates",
                                                 "rejected",
                                                 "optimizations",
                                                 "final_chi2",
                                                 "switched_off",
                                                 "odometry_rematched",
                                                 "window_edge_rejected",
                                                 "gate_rejected",
                                                 "inconsistent",
                                                 "certified",
                                                 "certificate_lambda_min",
                                                 "strained_edges",
                                                 "diverged",
                                                 "lost",
                                                 "chi2_ratio",
                                                 "unrepaired_losses"};
  return names;
}

std::map<std::string, double> GraphSlamEstimator::Statistics() const {
  const GraphSlamCounts& c = slam_.counts();
  const int unrepaired_losses = UnrepairedLosses();
  return {{"keyframes", c.keyframes},
          {"loop_closures", c.loop_closures},
          {"loop_candidates", c.loop_candidates},
          {"rejected", c.rejected},
          {"optimizations", c.optimizations},
          {"final_chi2", c.final_chi2},
          {"switched_off", c.switched_off},
          {"odometry_rematched", c.odometry_rematched},
          {"window_edge_rejected", c.window_edge_rejected},
          {"gate_rejected", c.gate_rejected},
          {"inconsistent", c.inconsistent},
          {"certified", c.certified ? 1.0 : 0.0},
          {"certificate_lambda_min", c.certificate_lambda_min},
          {"strained_edges", c.strained_edges},
          {"diverged", c.diverged || health_.Diverged() || unrepaired_losses > 0 ? 1.0 : 0.0},
          {"lost", health_.losses()},
          {"chi2_ratio", c.chi2_ratio},
          {"unrepaired_losses", unrepaired_losses}};
}

}  // namespace slamrig::slam
