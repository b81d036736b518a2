#include "slam/graph/graph_slam.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <queue>
#include <set>
#include <utility>

#include "slam/eval/chi_square.h"
#include "slam/graph/edge_error.h"
#include "slam/graph/odometry_release.h"
#include "slam/graph/optimality_certificate.h"
#include "slam/matching/correlative_matcher.h"
#include "slam/matching/grid_view.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/point_raster.h"
#include "slam/matching/scan_points.h"
#include "slam/types/check.h"
#include "slam/types/thread_pool.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
std::vector<std::string> GraphSlamOptions::Validate() const {
  Rules rules;
  rules.Nested("odometry_icp", odometry.Validate())
      .NonNegative("keyframe_distance_m", keyframe_distance_m)
      .NonNegative("keyframe_angle_rad", keyframe_angle_rad)
      .NonNegative("edge_sigma_xy_per_m", edge_sigma_xy_per_m)
      .Positive("edge_sigma_xy_floor_m", edge_sigma_xy_floor_m)
      .NonNegative("edge_sigma_yaw_per_rad", edge_sigma_yaw_per_rad)
      .NonNegative("edge_sigma_yaw_per_m", edge_sigma_yaw_per_m)
      .Positive("edge_sigma_yaw_floor_rad", edge_sigma_yaw_floor_rad)
      .NonNegative("odometry_check_nodes", odometry_check_nodes)
      .Positive("odometry_check_window_m", odometry_check_window_m)
      .Positive("odometry_check_window_rad", odometry_check_window_rad)
      .NonNegative("odometry_check_min_gain", odometry_check_min_gain)
      .InRange("odometry_check_wheel_confidence", odometry_check_wheel_confidence, 0.5, 1.0,
               Ends::kOpenLow)
      .NonNegative("odometry_check_wide_below", odometry_check_wide_below)
      .NonNegative("node_below_match_score", node_below_match_score)
      .Positive("odometry_check_wide_window_m", odometry_check_wide_window_m)
      .NonNegative("odometry_check_wide_min_score", odometry_check_wide_min_score)
      .AtLeast("loop_skip_keyframes", loop_skip_keyframes, 1)
      .NonNegative("loop_search_radius_m", loop_search_radius_m)
      .NonNegative("loop_radius_sigmas", loop_radius_sigmas)
      .Positive("loop_max_search_radius_m", loop_max_search_radius_m)
      .NonNegative("loop_max_candidates", loop_max_candidates)
      .NonNegative("submap_half_keyframes", submap_half_keyframes)
      .Positive("submap_resolution_m", submap_resolution_m)
      .Positive("submap_blur_m", submap_blur_m)
      .AtLeast("query_keyframes", query_keyframes, 1)
      .Nested("correlative", correlative.Validate())
      .Nested("loop_icp", loop_icp.Validate())
      .Fraction("loop_min_icp_score", loop_min_icp_score)
      .Positive("loop_max_refinement_m", loop_max_refinement_m)
      .Positive("loop_max_search_stddev_m", loop_max_search_stddev_m)
      .Require(loop_max_covariance_ratio > 1.0, "loop_max_covariance_ratio",
               loop_max_covariance_ratio, "must be > 1")
      .Positive("loop_chi2_gate", loop_chi2_gate)
      .Positive("loop_pairwise_chi2", loop_pairwise_chi2)
      .Positive("loop_sigma_xy_floor_m", loop_sigma_xy_floor_m)
      .Positive("loop_sigma_yaw_floor_rad", loop_sigma_yaw_floor_rad)
      .AtLeast("optimize_every_keyframes", optimize_every_keyframes, 1)
      .InRange("released_edge_information_scale", released_edge_information_scale, 0.0, 1.0,
               Ends::kOpenLow)
      .Fraction("diverged_strained_share", diverged_strained_share)
      .Nested("optimizer", optimizer.Validate())
      .InRange("threads", num_threads, 0, 1024);
  return rules.errors();
}

GraphSlam::GraphSlam(const GraphSlamOptions& options)
    : options_(options),
      odometry_(options.odometry),
      optimizer_(options.optimizer),
      consistency_(options.loop_pairwise_chi2),
      back_end_(ThreadCount(options.num_threads) > 1) {
  SLAMRIG_CHECK_VALID(options_, "GraphSlamOptions");
}

GraphSlam::~GraphSlam() = default;

Pose2 GraphSlam::Add(const LaserScan& scan, const Pose2& odometry_increment,
                     double odometry_gap_s) {
  // The front end, beside the back end's work on the previous node: ICP odometry never reads the
  // graph, and what decides a node is the front end's own.
  wheels_since_node_ = wheels_since_node_ * odometry_.calibration().Correct(odometry_increment);
  IcpOdometryStep step = odometry_.Add(scan, odometry_increment, odometry_gap_s);
  const bool first = nodes_decided_ == 0;
  const Pose2 since = first ? Pose2() : newest_node_odom_pose_.Between(step.pose);
  // A doubtful match becomes a node too, so that the odometry check judges it. (A failed match
  // is not: its prior is the wheels', which the next match corrects against the local map.)
  const bool matched = step.outcome == IcpOdometryOutcome::kMatched ||
                       step.outcome == IcpOdometryOutcome::kDegenerate;
  const bool doubtful = matched && step.score < options_.node_below_match_score;
  failed_since_node_ = failed_since_node_ || step.outcome == IcpOdometryOutcome::kMatchFailed;
  blind_since_node_ = blind_since_node_ || step.outcome == IcpOdometryOutcome::kMatchFailed ||
                      step.outcome == IcpOdometryOutcome::kNoPoints;
  std::optional<std::vector<Eigen::Vector2d>> node_points;
  if (first || since.translation().norm() >= options_.keyframe_distance_m ||
      std::abs(since.theta()) >= options_.keyframe_angle_rad || doubtful) {
    std::vector<Eigen::Vector2d> points = ScanToBasePoints(scan, options_.odometry.points);
    if (first || !points.empty()) node_points = std::move(points);
  }
  JoinBackEnd();  // every earlier node is placed
  last_step_ = std::move(step);
  last_scan_is_node_ = node_points.has_value();
  const int index = static_cast<int>(scan_node_.size());
  if (!node_points) {
    scan_node_.push_back(nodes_decided_ - 1);
    scan_from_node_.push_back(newest_node_odom_pose_.Between(last_step_.pose));
    return graph_.pose(scan_node_.back()) * scan_from_node_.back();
  }
  // A new node: its online pose is the previous node's as the graph has it and the front end's
  // motion since; the back end places it next (the odometry check, the loop search and an
  // optimisation move it from there), and the scans after it see where that put it.
  const Pose2 online = first ? Pose2() : graph_.pose(nodes_decided_ - 1) * since;
  const bool node_doubtful = doubtful || failed_since_node_;
  // Where the front end went blind since the last node the edge is the wheels' (calibrated)
  // increment: it carries their noise, as the front end measured it, not ICP's.
  std::optional<Eigen::Vector2d> blind_noise;
  if (blind_since_node_ && options_.blind_edge_odometry_noise) {
    blind_noise = odometry_.noise_scale();
  }
  WheelMotion wheels;
  wheels.relative = wheels_since_node_;
  wheels.sigmas =
      options_.odometry.IncrementSigmas(wheels.relative).cwiseProduct(odometry_.noise_scale());
  failed_since_node_ = false;
  blind_since_node_ = false;
  newest_node_odom_pose_ = last_step_.pose;
  wheels_since_node_ = Pose2();
  scan_node_.push_back(nodes_decided_++);
  scan_from_node_.push_back(Pose2());
  auto place = [this, index, pose = last_step_.pose, node_doubtful, blind_noise, wheels,
                points = std::move(*node_points)]() mutable {
    AddNode(index, pose, node_doubtful, blind_noise, wheels, std::move(points));
    SearchLoops();
    const int added = static_cast<int>(nodes_.size()) - nodes_at_last_optimization_;
    if (pending_closure_ && added >= options_.optimize_every_keyframes) Optimize();
  };
  back_end_.Start(std::move(place));
  return online;
}

void GraphSlam::JoinBackEnd() const {
  back_end_.Wait();  // rethrows what the back end threw
}

void GraphSlam::Finish() {
  JoinBackEnd();
  if (pending_closure_) Optimize();
  if (options_.loop_drop_strained) DropStrainedClosures();
  CheckOptimality();
  JudgeConsistency();
}

bool GraphSlam::ReleaseWrongOdometryEdge() {
  OdometryReleaseOptions release_options;
  release_options.optimizer = options_.optimizer;
  release_options.information_scale = options_.released_edge_information_scale;
  auto eligible = [this](std::size_t e) { return !released_.contains(graph_.edges()[e].to); };
  // As for the odometry check's re-match: the wheels must allow the released edge's distance.
  auto plausible = [this](std::size_t e, const Pose2& relative) {
    const PoseGraphEdge& edge = graph_.edges()[e];
    return WheelsAllow(nodes_[static_cast<std::size_t>(edge.to)].wheels, edge.measurement,
                       relative);
  };
  const std::optional<OdometryRelease> release =
      slam::ReleaseWrongOdometryEdge(&graph_, release_options, eligible, plausible);
  if (!release) return false;
  released_.insert(graph_.edges()[release->edge].to);
  edge_variances_[release->edge] /= options_.released_edge_information_scale;
  ++counts_.released_odometry;
  counts_.final_chi2 = release->summary.final_chi2;
  switches_ = release->summary.switches;
  ++counts_.optimizations;
  return true;
}

void GraphSlam::DropStrainedClosures() {
  while (true) {
    if (options_.release_wrong_odometry && ReleaseWrongOdometryEdge()) continue;
    double worst = kEdgeChi2P99;
    std::optional<std::size_t> worst_closure;
    for (std::size_t i = 0; i < closures_.size(); ++i) {
      const std::size_t e = closure_edges_[i];
      if (SwitchedOff(e)) continue;
      const double chi2 = EdgeChi2(graph_, graph_.edges()[e]);
      if (chi2 > worst) {
        worst = chi2;
        worst_closure = i;
      }
    }
    if (!worst_closure) return;
    RemoveClosure(*worst_closure);
    ++counts_.dropped_strained;
    Optimize();
  }
}

void GraphSlam::KeepEdges(const std::function<bool(std::size_t)>& keep) {
  PoseGraph rebuilt;
  for (const PoseGraphVertex& v : graph_.vertices()) rebuilt.AddVertex(v.id, v.pose, v.fixed);
  std::vector<Eigen::Vector2d> variances;
  for (std::size_t e = 0; e < graph_.edges().size(); ++e) {
    if (!keep(e)) continue;
    rebuilt.AddEdge(graph_.edges()[e]);
    variances.push_back(edge_variances_[e]);
  }
  graph_ = std::move(rebuilt);
  edge_variances_ = std::move(variances);
  switches_.clear();
}

bool GraphSlam::SwitchedOff(std::size_t e) const {
  return e < switches_.size() && switches_[e] < 0.5;
}

void GraphSlam::RemoveClosure(std::size_t i) {
  const std::size_t removed = closure_edges_[i];
  KeepEdges([removed](std::size_t e) { return e != removed; });
  closure_edges_.erase(closure_edges_.begin() + static_cast<std::ptrdiff_t>(i));
  for (std::size_t& e : closure_edges_) e -= e > removed;
  closures_.erase(closures_.begin() + static_cast<std::ptrdiff_t>(i));
  --counts_.loop_closures;
}

void GraphSlam::JudgeConsistency() {
  int kept = 0, strained = 0;
  double chi2 = 0.0;
  const std::vector<PoseGraphEdge>& edges = graph_.edges();
  strained_.assign(edges.size(), false);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (SwitchedOff(e)) continue;
    ++kept;
    const double edge_chi2 = EdgeChi2(graph_, edges[e]);
    chi2 += edge_chi2;
    strained_[e] = edge_chi2 > kEdgeChi2P99;
    strained += strained_[e];
  }
  counts_.strained_edges = strained;
  const int dof = 3 * kept - 3 * (static_cast<int>(graph_.vertices().size()) - 1);
  if (dof > 0) counts_.chi2_ratio = chi2 / ChiSquareQuantile(0.99, dof);
  counts_.diverged =
      kept > 0 && static_cast<double>(strained) > options_.diverged_strained_share * kept;
}

void GraphSlam::CheckOptimality() {
  if (graph_.edges().empty()) return;
  OptimalityCertificateOptions certificate;
  certificate.optimizer = options_.optimizer;
  certificate.optimizer.robust_loss = RobustLoss::kNone;  // the weights carry it
  const OptimalityCertificate c =
      CertifyOptimality(WithRobustWeights(graph_, options_.optimizer, switches_), certificate);
  counts_.certified = c.certified;
  counts_.certificate_lambda_min = c.lambda_min;
}

std::vector<Pose2> GraphSlam::Poses() const {
  JoinBackEnd();
  std::vector<Pose2> poses;
  poses.reserve(scan_node_.size());
  for (std::size_t i = 0; i < scan_node_.size(); ++i) {
    poses.push_back(graph_.pose(scan_node_[i]) * scan_from_node_[i]);
  }
  return poses;
}

std::vector<LoopClosure> GraphSlam::loop_closures() const {
  JoinBackEnd();
  std::vector<LoopClosure> kept;
  for (std::size_t i = 0; i < closures_.size(); ++i) {
    const std::size_t e = closure_edges_[i];
    if (SwitchedOff(e)) continue;
    kept.push_back(closures_[i]);
  }
  return kept;
}

std::vector<LoopClosure> GraphSlam::UnstrainedLoopClosures() const {
  JoinBackEnd();
  std::vector<LoopClosure> agreed;
  for (std::size_t i = 0; i < closures_.size(); ++i) {
    const std::size_t e = closure_edges_[i];
    if (SwitchedOff(e)) continue;
    if (e < strained_.size() && strained_[e]) continue;
    agreed.push_back(closures_[i]);
  }
  return agreed;
}

void GraphSlam::AddNode(int scan, const Pose2& odom_pose, bool doubtful,
                        const std::optional<Eigen::Vector2d>& blind_noise,
                        const WheelMotion& wheels, std::vector<Eigen::Vector2d> points) {
  const int id = static_cast<int>(nodes_.size());
  Node node{scan, odom_pose, std::move(points), Eigen::Vector2d::Zero(), Pose2(), wheels};
  if (nodes_.empty()) {
    graph_.AddVertex(id, Pose2(), /*fixed=*/true);
  } else {
    // When the previous node was re-placed, ICP odometry may have kept its wrong frame (the next
    // relative pose is right as it is) or found its way back (the next one is right from the node
    // before): both are tried.
    const Pose2 icp_relative = nodes_.back().odom_pose.Between(odom_pose);
    const Pose2 relative = CheckedRelative(
        icp_relative, nodes_.back().rematch_offset * icp_relative, doubtful, wheels, node.points);
    node.rematch_offset = relative.Inverse() * icp_relative;
    const double d = relative.translation().norm();
    double sxy = options_.edge_sigma_xy_per_m * d + options_.edge_sigma_xy_floor_m;
    double syaw = options_.edge_sigma_yaw_per_rad * std::abs(relative.theta()) +
                  options_.edge_sigma_yaw_per_m * d + options_.edge_sigma_yaw_floor_rad;
    if (blind_noise) {
      const Eigen::Vector2d odometry_sigmas =
          blind_noise->cwiseProduct(options_.odometry.IncrementSigmas(relative));
      sxy = std::max(sxy, odometry_sigmas.x());
      syaw = std::max(syaw, odometry_sigmas.y());
    }
    node.edge_variance = {sxy * sxy, syaw * syaw};
    graph_.AddVertex(id, graph_.pose(id - 1) * relative);
    PoseGraphEdge edge{
        id - 1, id, relative,
        Eigen::Vector3d(1.0 / (sxy * sxy), 1.0 / (sxy * sxy), 1.0 / (syaw * syaw)).asDiagonal(),
        EdgeKind::kOdometry};
    graph_.AddEdge(edge);
    edge_variances_.push_back(node.edge_variance);
    chain_.Append(relative, sxy * sxy, syaw * syaw);
  }
  nodes_.push_back(std::move(node));
  ++counts_.keyframes;
}

bool GraphSlam::WheelsAllow(const WheelMotion& wheels, const Pose2& front_end,
                            const Pose2& relative) const {
  if (options_.odometry_check_wheel_confidence >= 1.0) return true;
  auto signed_distance = [](const Pose2& p) {
    return std::copysign(p.translation().norm(), p.translation().x());
  };
  auto wheel_chi2 = [&](const Pose2& p) {
    const double sxy = std::max(wheels.sigmas.x(), 1e-6);
    const double e = signed_distance(p) - signed_distance(wheels.relative);
    return e * e / (sxy * sxy);
  };
  const double allowed = std::max(wheel_chi2(front_end),
                                  ChiSquareQuantile(options_.odometry_check_wheel_confidence, 1.0));
  return wheel_chi2(relative) <= allowed;
}

Pose2 GraphSlam::CheckedRelative(const Pose2& icp_relative, const Pose2& alternative, bool doubtful,
                                 const WheelMotion& wheels,
                                 const std::vector<Eigen::Vector2d>& points) {
  const int newest = static_cast<int>(nodes_.size()) - 1;
  if (options_.odometry_check_nodes == 0 || points.size() < 10) return icp_relative;
  std::vector<Eigen::Vector2d> reference;
  for (int k = std::max(0, newest - options_.odometry_check_nodes + 1); k <= newest; ++k) {
    const Pose2 newest_from_k = graph_.pose(newest).Between(graph_.pose(k));
    for (const Eigen::Vector2d& p : nodes_[k].points) reference.push_back(newest_from_k * p);
  }
  if (reference.size() < 10) return icp_relative;
  const PointRaster raster =
      RasterOf(reference, options_.submap_resolution_m, options_.submap_blur_m);
  const std::vector<Eigen::Vector2d> query = Thinned(points, options_.submap_resolution_m);
  // A correlative search around `guess` within the windows, refined by ICP against the points.
  auto rematch = [&](const Pose2& guess, double window_m, double window_rad,
                     bool coarse_fallback) -> std::optional<Pose2> {
    CorrelativeMatcherOptions search = options_.correlative;
    search.linear_window_m = window_m;
    search.angular_window_rad = window_rad;
    const std::optional<MatchResult> coarse =
        CorrelativeMatcher(search, raster.view).Match(query, guess);
    if (!coarse) return std::nullopt;
    const std::optional<MatchResult> fine =
        IcpMatcher(options_.loop_icp, reference).Match(points, coarse->pose);
    // ICP's refinement where it holds; else, for the wide search, the correlative pose itself (a
    // scan after a lost turn overlaps the last nodes only in part).
    if (!fine || fine->score < options_.loop_min_icp_score) {
      return coarse_fallback ? std::optional<Pose2>(coarse->pose) : std::nullopt;
    }
    return fine->pose;
  };
  // The wheels' distance as a yardstick: a re-match may not put the node farther from the
  // previous one, or nearer, than the wheels say by more (in their sigmas) than ICP odometry's pose
  // did, or than the gate. Where the scans leave a direction nearly free (a long wall seen past a
  // glass facade, which answers only beside the robot) a re-match can fit the last nodes better
  // by standing still, one or two node spacings back, which the wheels' distance rules out. Which
  // way the wheels went is no yardstick: a turn logged a scan late (edmonton) or missed in a gap
  // puts it off by tenths of a radian where the re-match is right. Distances are signed, forwards
  // or backwards in the previous node's frame: a re-match two node spacings back is as far as the
  // wheels say, the wrong way.
  auto plausible = [&](const Pose2& p) { return WheelsAllow(wheels, icp_relative, p); };
  Pose2 relative = icp_relative;
  double best_score = RasterScore(raster, query, relative);
  if (!(alternative == icp_relative) && plausible(alternative)) {
    const double score = RasterScore(raster, query, alternative);
    if (score > best_score) {
      relative = alternative;
      best_score = score;
    }
  }
  Pose2 best = relative;
  if (const std::optional<Pose2> local = rematch(relative, options_.odometry_check_window_m,
                                                 options_.odometry_check_window_rad, false)) {
    const double score = RasterScore(raster, query, *local);
    if (score > best_score + options_.odometry_check_min_gain && plausible(*local)) {
      best = *local;
      best_score = score;
    }
  }
  if (doubtful && best_score < options_.odometry_check_wide_below) {
    if (const std::optional<Pose2> wide =
            rematch(relative, options_.odometry_check_wide_window_m, std::numbers::pi, true)) {
      const double score = RasterScore(raster, query, *wide);
      if (score >= options_.odometry_check_wide_min_score &&
          score > best_score + options_.odometry_check_min_gain && plausible(*wide)) {
        best = *wide;
        best_score = score;
      }
    }
  }
  if (!(best == icp_relative)) ++counts_.odometry_rematched;
  return best;
}

std::vector<Eigen::Vector2d> GraphSlam::PathVariances() const {
  // Dijkstra from the newest node on the position variance. Walking back from node u along an
  // edge adds the edge's own xy variance and its yaw variance times the squared lever from u to
  // the newest node: a heading error in the edge turns everything after it about u, and moves
  // the newest node by |p_newest - p_u| times the error. The lever is the straight distance (the
  // current estimate's), not the path's length: a loop that comes back near its start has short
  // levers at both ends.
  struct State {
    double xy = std::numeric_limits<double>::infinity();
    double yaw = 0.0;
  };
  const std::size_t n = nodes_.size();
  std::vector<std::vector<std::pair<int, std::size_t>>> adjacent(n);
  const std::vector<PoseGraphEdge>& edges = graph_.edges();
  for (std::size_t e = 0; e < edges.size(); ++e) {
    adjacent[edges[e].from].emplace_back(edges[e].to, e);
    adjacent[edges[e].to].emplace_back(edges[e].from, e);
  }
  std::vector<State> state(n);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  state[n - 1] = State{0.0, 0.0};
  const Eigen::Vector2d newest = graph_.pose(static_cast<int>(n - 1)).translation();
  queue.emplace(0.0, static_cast<int>(n - 1));
  while (!queue.empty()) {
    const auto [cost, u] = queue.top();
    queue.pop();
    if (cost > state[u].xy) continue;
    const double lever_sq = (graph_.pose(u).translation() - newest).squaredNorm();
    for (const auto& [w, e] : adjacent[u]) {
      const State next{state[u].xy + edge_variances_[e].x() + edge_variances_[e].y() * lever_sq,
                       state[u].yaw + edge_variances_[e].y()};
      if (next.xy < state[w].xy) {
        state[w] = next;
        queue.emplace(next.xy, w);
      }
    }
  }
  std::vector<Eigen::Vector2d> variance;
  variance.reserve(n);
  for (const State& s : state) variance.emplace_back(s.xy, s.yaw);
  return variance;
}

void GraphSlam::SearchLoops() {
  const int current = static_cast<int>(nodes_.size()) - 1;
  const int newest_candidate = current - options_.loop_skip_keyframes;
  if (newest_candidate < 0 || options_.loop_max_candidates == 0) return;
  const std::vector<Eigen::Vector2d> variance = PathVariances();
  const Pose2& here = graph_.pose(current);
  // Candidates: within the radius grown by the uncertainty accumulated since them, nearest first.
  std::vector<std::pair<double, int>> candidates;
  for (int j = 0; j <= newest_candidate; ++j) {
    const double d = (graph_.pose(j).translation() - here.translation()).norm();
    const double var_xy = variance[j].x();
    const double radius =
        std::min(options_.loop_max_search_radius_m,
                 options_.loop_search_radius_m + options_.loop_radius_sigmas * std::sqrt(var_xy));
    if (d <= radius) candidates.emplace_back(d, j);
  }
  std::sort(candidates.begin(), candidates.end());
  if (static_cast<int>(candidates.size()) > options_.loop_max_candidates) {
    candidates.resize(static_cast<std::size_t>(options_.loop_max_candidates));
  }
  for (const auto& [d, j] : candidates) {
    ++counts_.loop_candidates;
    std::optional<PoseGraphEdge> edge = TryClosure(j, variance[j]);
    if (!edge) {
      ++counts_.rejected;
      rejected_.push_back(
          {nodes_[j].scan, nodes_[current].scan, graph_.pose(j).Between(graph_.pose(current))});
      continue;
    }
    AcceptClosure(*edge, {nodes_[j].scan, nodes_[current].scan, edge->measurement});
  }
}

void GraphSlam::AddClosureEdge(const PoseGraphEdge& edge, const LoopClosure& closure) {
  closure_edges_.push_back(graph_.edges().size());
  graph_.AddEdge(edge);
  const Eigen::Matrix3d covariance = edge.information.inverse();
  edge_variances_.emplace_back(covariance(0, 0) + covariance(1, 1), covariance(2, 2));
  closures_.push_back(closure);
  ++counts_.loop_closures;
  pending_closure_ = true;
}

void GraphSlam::AcceptClosure(const PoseGraphEdge& edge, const LoopClosure& closure) {
  if (options_.loop_consistency == LoopConsistency::kNone) {
    AddClosureEdge(edge, closure);
    return;
  }
  hypothesis_edges_.push_back(edge);
  hypothesis_closures_.push_back(closure);
  const bool changed =
      consistency_.Add({edge.from, edge.to, edge.measurement, edge.information.inverse()}, chain_);
  const std::vector<int>& kept = consistency_.kept();
  counts_.inconsistent = consistency_.size() - static_cast<int>(kept.size());
  if (!changed) {
    if (!kept.empty() && kept.back() == consistency_.size() - 1) AddClosureEdge(edge, closure);
    return;
  }
  // The consistent set changed: the graph keeps its vertices (at their current estimates) and
  // odometry edges, and takes the kept closures in place of the ones it had.
  KeepEdges([this](std::size_t e) { return graph_.edges()[e].kind != EdgeKind::kLoopClosure; });
  closure_edges_.clear();
  closures_.clear();
  counts_.loop_closures = 0;
  for (const int k : kept) AddClosureEdge(hypothesis_edges_[k], hypothesis_closures_[k]);
  // At once: the estimate still bends to the closures just dropped, and the loop search reads it.
  Optimize();
}

std::optional<PoseGraphEdge> GraphSlam::TryClosure(int candidate, const Eigen::Vector2d& variance) {
  const int current = static_cast<int>(nodes_.size()) - 1;
  const Pose2 guess = graph_.pose(candidate).Between(graph_.pose(current));
  const double var_xy = variance.x();
  const double var_yaw = variance.y();

  // The candidate's submap (its neighbours that are old enough) and the current side's points.
  std::vector<Eigen::Vector2d> submap;
  const int newest = current - options_.loop_skip_keyframes;
  for (int k = std::max(0, candidate - options_.submap_half_keyframes);
       k <= std::min(newest, candidate + options_.submap_half_keyframes); ++k) {
    const Pose2 candidate_from_k = graph_.pose(candidate).Between(graph_.pose(k));
    for (const Eigen::Vector2d& p : nodes_[k].points) submap.push_back(candidate_from_k * p);
  }
  std::vector<Eigen::Vector2d> query;
  for (int k = std::max(0, current - options_.query_keyframes + 1); k <= current; ++k) {
    const Pose2 current_from_k = graph_.pose(current).Between(graph_.pose(k));
    for (const Eigen::Vector2d& p : nodes_[k].points) query.push_back(current_from_k * p);
  }
  query = Thinned(query, options_.submap_resolution_m);
  if (submap.size() < 10 || query.size() < 10) return std::nullopt;

  // Correlative search within the uncertainty (Olson 2009), then ICP against the points.
  const PointRaster raster = RasterOf(submap, options_.submap_resolution_m, options_.submap_blur_m);
  CorrelativeMatcherOptions search = options_.correlative;
  search.linear_window_m =
      std::min(search.linear_window_m,
               options_.loop_search_radius_m + options_.loop_radius_sigmas * std::sqrt(var_xy));
  search.angular_window_rad =
      std::min(search.angular_window_rad, 0.1 + options_.loop_radius_sigmas * std::sqrt(var_yaw));
  const std::optional<MatchResult> coarse =
      CorrelativeMatcher(search, raster.view).Match(query, guess);
  if (!coarse) return std::nullopt;
  // A best pose in the window's outermost ring is no peak of the search: the fit still rises
  // outwards, beyond what the graph's uncertainty allows (an alias whose own peak lies outside).
  const Eigen::Vector2d offset = coarse->pose.translation() - guess.translation();
  if (offset.cwiseAbs().maxCoeff() > search.linear_window_m - options_.submap_resolution_m) {
    ++counts_.window_edge_rejected;
    return std::nullopt;
  }
  const std::optional<MatchResult> fine =
      IcpMatcher(options_.loop_icp, submap).Match(query, coarse->pose);
  if (!fine || fine->score < options_.loop_min_icp_score ||
      (fine->pose.translation() - coarse->pose.translation()).norm() >
          options_.loop_max_refinement_m) {
    return std::nullopt;
  }

  // Ambiguity: a flat score or an elongated ICP covariance (a corridor) says nothing reliable.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> coarse_spread(
      coarse->covariance.topLeftCorner<2, 2>());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> fine_spread(
      fine->covariance.topLeftCorner<2, 2>());
  if (coarse_spread.eigenvalues()[1] >
          options_.loop_max_search_stddev_m * options_.loop_max_search_stddev_m ||
      fine_spread.eigenvalues()[1] >
          options_.loop_max_covariance_ratio * std::max(fine_spread.eigenvalues()[0], 1e-300)) {
    return std::nullopt;
  }

  // Geometric verification: the closure must agree with the graph within its uncertainty.
  Eigen::Matrix3d measurement_covariance = fine->covariance;
  measurement_covariance(0, 0) += options_.loop_sigma_xy_floor_m * options_.loop_sigma_xy_floor_m;
  measurement_covariance(1, 1) += options_.loop_sigma_xy_floor_m * options_.loop_sigma_xy_floor_m;
  measurement_covariance(2, 2) +=
      options_.loop_sigma_yaw_floor_rad * options_.loop_sigma_yaw_floor_rad;
  const Eigen::Matrix3d gate_covariance =
      measurement_covariance +
      Eigen::Vector3d(var_xy, var_xy, var_yaw).asDiagonal().toDenseMatrix();
  const Eigen::Vector3d error(fine->pose.x() - guess.x(), fine->pose.y() - guess.y(),
                              NormalizeAngle(fine->pose.theta() - guess.theta()));
  const double chi2 = error.dot(gate_covariance.ldlt().solve(error));
  if (!(chi2 <= options_.loop_chi2_gate)) {
    ++counts_.gate_rejected;
    return std::nullopt;
  }

  PoseGraphEdge edge;
  edge.from = candidate;
  edge.to = current;
  edge.measurement = fine->pose;
  edge.information = measurement_covariance.inverse();
  edge.information = 0.5 * (edge.information + edge.information.transpose());
  edge.kind = EdgeKind::kLoopClosure;
  return edge;
}

void GraphSlam::Optimize() {
  const PoseGraphSummary summary = optimizer_.Optimize(&graph_);
  counts_.final_chi2 = summary.final_chi2;
  switches_ = summary.switches;
  counts_.switched_off = 0;
  for (const std::size_t e : closure_edges_) {
    counts_.switched_off += SwitchedOff(e);
  }
  ++counts_.optimizations;
  pending_closure_ = false;
  nodes_at_last_optimization_ = static_cast<int>(nodes_.size());
}

}  // namespace slamrig::slam
