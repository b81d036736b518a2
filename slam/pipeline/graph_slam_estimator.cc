#include "slam/pipeline/graph_slam_estimator.h"

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> GraphSlamEstimatorOptions::Validate() const {
  std::vector<std::string> errors = graph.Validate();
  AppendErrors(&errors, PrefixErrors("map", map.Validate()));
  return errors;
}

GraphSlamEstimator::GraphSlamEstimator(const GraphSlamEstimatorOptions& options,
                                       const EstimatorContext& /*context*/)
    : options_(options), slam_(options.graph), map_(options.map) {}

ScanEstimate GraphSlamEstimator::AddScan(const SyncedScan& scan) {
  const Pose2 pose = slam_.Add(scan.scan, scan.increment);
  map_.InsertScan(scan.scan, pose);
  scans_.push_back(scan.scan);
  return {pose, std::nullopt, {}, std::nullopt};
}

void GraphSlamEstimator::Finish() {
  slam_.Finish();
  // The map from the optimised poses.
  map_ = OccupancyGrid(options_.map);
  const std::vector<Pose2> poses = slam_.Poses();
  for (std::size_t i = 0; i < scans_.size(); ++i) map_.InsertScan(scans_[i], poses[i]);
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

std::map<std::string, double> GraphSlamEstimator::Statistics() const {
  const GraphSlamCounts& c = slam_.counts();
  return {{"keyframes", c.keyframes},
          {"loop_closures", c.loop_closures},
          {"loop_candidates", c.loop_candidates},
          {"rejected", c.rejected},
          {"optimizations", c.optimizations},
          {"final_chi2", c.final_chi2},
          {"switched_off", c.switched_off}};
}

}  // namespace slamrig::slam
