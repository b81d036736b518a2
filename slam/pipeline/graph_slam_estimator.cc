#include "slam/pipeline/graph_slam_estimator.h"

#include <algorithm>

#include "slam/matching/scan_points.h"
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
    : options_(options),
      slam_(GraphOptions(options, context)),
      map_(options.map),
      own_odometry_(context.own_odometry) {}

ScanEstimate GraphSlamEstimator::AddScan(const SyncedScan& scan) {
  const Pose2 pose = slam_.Add(scan.scan, scan.increment, scan.odometry_gap_s);
  // Only the graph's nodes enter the map: inserting every scan at the scan rate wears thin walls
  // away (grazing beams clear them) and over-weights the places where the robot stood still.
  if (slam_.last_scan_is_node()) {
    map_.InsertScan(scan.scan, pose);
    node_scans_.push_back(scan.scan);
  }
  wheel_increments_.push_back(scan.increment);
  odometry_gaps_.push_back(scan.odometry_gap_s > options_.graph.odometry.search.gap_s);
  ScanEstimate estimate;
  estimate.pose = pose;
  estimate.lost = front_end_health_.Judge(slam_.last_step(), &estimate.trace);
  const int losses = health_.losses();
  health_.Add(*estimate.lost);
  if (*estimate.lost) {
    // A lost scan is placed by the odometry: the bound on what its loss left grows by the
    // odometry's noise over its increment (the front end's model, scaled by the noise it
    // measured on its clear matches).
    if (health_.losses() > losses) {
      blind_.Start();
      loss_bounds_m_.push_back(0.0);
    }
    blind_.Add(scan.increment, options_.graph.odometry.IncrementSigmas(scan.increment)
                                   .cwiseProduct(slam_.front_end().noise_scale()));
    loss_bounds_m_.back() = blind_.bound_m();
  }
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
  JudgeTurnsAgainstWheels();
  // The nodes' views where the final poses say the robot came back.
  std::vector<Pose2> poses;
  std::vector<std::vector<Eigen::Vector2d>> points;
  poses.reserve(node_scans_.size());
  points.reserve(node_scans_.size());
  for (std::size_t k = 0; k < node_scans_.size(); ++k) {
    poses.push_back(graph.pose(static_cast<int>(k)));
    points.push_back(ScanToBasePoints(node_scans_[k], options_.graph.odometry.points));
  }
  revisits_ = CheckRevisits(poses, points);
}

void GraphSlamEstimator::JudgeTurnsAgainstWheels() {
  if (!own_odometry_) return;
  const std::vector<Pose2> poses = slam_.Poses();
  const std::size_t n = std::min(poses.size(), wheel_increments_.size());
  // The wheels' heading noise on this run: the front end's model (a share of the turn, a little
  // per metre) scaled by the median of the final poses' turn residuals against the wheels over
  // the scans that turn (where the share of the turn is the model's larger term), each in units
  // of the model's sigma (a median of |N(0, 1)| is 0.6745). A median: a wrong turn or two of
  // the estimate's do not raise it; wheels that scatter in every turn do.
  const IcpOdometryOptions& model = options_.graph.odometry;
  std::vector<double> residuals;
  for (std::size_t i = 1; i < n; ++i) {
    const Pose2& wheels = wheel_increments_[i];
    const double sigma = model.IncrementSigmas(wheels).y();
    const double turn_sigma = model.sigma_yaw_per_rad * std::abs(wheels.theta());
    if (odometry_gaps_[i] || !(turn_sigma > sigma / 2.0)) continue;
    const double residual = NormalizeAngle(poses[i - 1].Between(poses[i]).theta() - wheels.theta());
    residuals.push_back(std::abs(residual) / sigma);
  }
  double scale = 1.0;
  if (!residuals.empty()) {
    const auto middle = residuals.begin() + static_cast<std::ptrdiff_t>(residuals.size() / 2);
    std::nth_element(residuals.begin(), middle, residuals.end());
    scale = std::max(1.0, *middle / 0.6745);
  }
  WheelAgreement agreement;
  for (std::size_t i = 1; i < n; ++i) {
    if (odometry_gaps_[i]) {
      agreement.Reset();
      continue;
    }
    const Pose2& wheels = wheel_increments_[i];
    const Pose2 estimate = poses[i - 1].Between(poses[i]);
    // The noise grows with the turn the robot made, which the wheels may under-report (a turn
    // logged with the wrong sign): the larger of the two turns sets it.
    const Pose2 turned(wheels.x(), wheels.y(),
                       std::max(std::abs(wheels.theta()), std::abs(estimate.theta())));
    // Observability 1: the turns alone are judged; the front end holds the distance to the
    // wheels itself (the odometry check).
    agreement.Add(estimate, wheels, 1.0, scale * model.IncrementSigmas(turned).y());
  }
  wheel_heading_contradiction_rad_ = agreement.heading_contradicted_rad();
  wheel_heading_noise_scale_ = scale;
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

std::vector<double> GraphSlamEstimator::UnrepairedLossBounds() const {
  const std::vector<LoopClosure> closures = slam_.UnstrainedLoopClosures();
  std::vector<double> bounds;
  const std::vector<std::pair<int, int>>& losses = health_.loss_scans();
  for (std::size_t i = 0; i < losses.size(); ++i) {
    // A closure repairs the loss when it spans it: from a scan before it to one after it.
    const bool repaired = std::any_of(closures.begin(), closures.end(), [&](const LoopClosure& c) {
      return c.from_scan < losses[i].first && c.to_scan > losses[i].second;
    });
    if (!repaired) bounds.push_back(i < loss_bounds_m_.size() ? loss_bounds_m_[i] : 0.0);
  }
  return bounds;
}

int GraphSlamEstimator::UnrepairedLosses() const {
  return static_cast<int>(UnrepairedLossBounds().size());
}

const std::vector<std::string>& GraphSlamEstimator::StatisticNames() {
  static const std::vector<std::string> names =
      RevisitAgreement::WithStatisticNames({"keyframes",
                                            "loop_closures",
                                            "loop_candidates",
                                            "rejected",
                                            "optimizations",
                                            "final_chi2",
                                            "switched_off",
                                            "dropped_strained",
                                            "released_odometry",
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
                                            "unrepaired_losses",
                                            "unrepaired_error_bound_m",
                                            "wheel_heading_contradiction_rad",
                                            "wheel_heading_noise_scale"});
  return names;
}

std::map<std::string, double> GraphSlamEstimator::Statistics() const {
  const GraphSlamCounts& c = slam_.counts();
  const std::vector<double> unrepaired = UnrepairedLossBounds();
  const double bound_m =
      unrepaired.empty() ? 0.0 : *std::max_element(unrepaired.begin(), unrepaired.end());
  // Strained edges, a loss that may have left more than kDivergedErrorM, a turn the wheels
  // contradict, or a map that contradicts itself where the robot came back.
  const bool diverged = c.diverged || bound_m > kDivergedErrorM ||
                        wheel_heading_contradiction_rad_ > 0.0 || revisits_.contradicts({});
  std::map<std::string, double> statistics = {
      {"keyframes", c.keyframes},
      {"loop_closures", c.loop_closures},
      {"loop_candidates", c.loop_candidates},
      {"rejected", c.rejected},
      {"optimizations", c.optimizations},
      {"final_chi2", c.final_chi2},
      {"switched_off", c.switched_off},
      {"dropped_strained", c.dropped_strained},
      {"released_odometry", c.released_odometry},
      {"odometry_rematched", c.odometry_rematched},
      {"window_edge_rejected", c.window_edge_rejected},
      {"gate_rejected", c.gate_rejected},
      {"inconsistent", c.inconsistent},
      {"certified", c.certified ? 1.0 : 0.0},
      {"certificate_lambda_min", c.certificate_lambda_min},
      {"strained_edges", c.strained_edges},
      {"diverged", diverged ? 1.0 : 0.0},
      {"lost", health_.losses()},
      {"chi2_ratio", c.chi2_ratio},
      {"unrepaired_losses", static_cast<double>(unrepaired.size())},
      {"unrepaired_error_bound_m", bound_m},
      {"wheel_heading_contradiction_rad", wheel_heading_contradiction_rad_},
      {"wheel_heading_noise_scale", wheel_heading_noise_scale_}};
  revisits_.AppendStatistics(&statistics);
  return statistics;
}

}  // namespace slamrig::slam
