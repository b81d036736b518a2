#include "slam/matching/icp_odometry.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include "slam/matching/map_frame_drift.h"
#include "slam/matching/solution_remapping.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// `pose`'s squared Mahalanobis distance from `prior` with independent x, y (sigma.x()) and yaw
// (sigma.y()) deviations.
double SquaredMahalanobis(const Pose2& prior, const Pose2& pose, const Eigen::Vector2d& sigma) {
  const Pose2 d = prior.Between(pose);
  return d.translation().squaredNorm() / (sigma.x() * sigma.x()) +
         d.theta() * d.theta() / (sigma.y() * sigma.y());
}

// `points_base` (base frame) placed at `pose`.
std::vector<Eigen::Vector2d> Placed(const std::vector<Eigen::Vector2d>& points_base,
                                    const Pose2& pose) {
  std::vector<Eigen::Vector2d> placed;
  placed.reserve(points_base.size());
  for (const Eigen::Vector2d& p : points_base) placed.push_back(pose * p);
  return placed;
}

}  // namespace

std::vector<std::string> IcpOdometrySearchOptions::Validate() const {
  Rules rules;
  rules.NonNegative("sigmas", sigmas)
      .NonNegative("trigger_window_m", trigger_window_m)
      .NonNegative("trigger_window_rad", trigger_window_rad)
      .Positive("max_window_m", max_window_m)
      .Require(max_window_rad > 0.0 && max_window_rad <= std::numbers::pi, "max_window_rad",
               max_window_rad, "must be in (0, pi]")
      .Positive("resolution_m", resolution_m)
      .Positive("blur_m", blur_m)
      .NonNegative("min_gain", min_gain)
      .NonNegative("prior_weight", prior_weight)
      .Fraction("adapt_rate", adapt_rate)
      .NonNegative("gap_s", gap_s)
      .AtLeast("blind_scans", blind_scans, 0)
      .NonNegative("wide_window_m", wide_window_m)
      .Require(wide_window_rad >= 0.0 && wide_window_rad <= std::numbers::pi, "wide_window_rad",
               wide_window_rad, "must be in [0, pi]");
  return rules.errors();
}

std::vector<std::string> IcpOdometryOptions::Validate() const {
  Rules rules;
  rules.AtLeast("local_map_keyframes", local_map_keyframes, 1)
      .NonNegative("local_map_voxel_m", local_map_voxel_m)
      .NonNegative("keyframe_distance_m", keyframe_distance_m)
      .NonNegative("keyframe_angle_rad", keyframe_angle_rad)
      .Positive("max_translation_stddev_m", max_translation_stddev_m)
      .Require(max_covariance_ratio > 1.0, "max_covariance_ratio", max_covariance_ratio,
               "must be > 1")
      .Positive("max_yaw_stddev_rad", max_yaw_stddev_rad)
      .Fraction("weak_direction_ratio", weak_direction_ratio)
      .Positive("weak_direction_gate_sigmas", weak_direction_gate_sigmas)
      .Fraction("min_score", min_score)
      .Positive("max_correction_m", max_correction_m)
      .Positive("max_correction_rad", max_correction_rad)
      .NonNegative("sigma_xy_per_m", sigma_xy_per_m)
      .NonNegative("sigma_xy_floor_m", sigma_xy_floor_m)
      .NonNegative("sigma_yaw_per_rad", sigma_yaw_per_rad)
      .NonNegative("sigma_yaw_per_m", sigma_yaw_per_m)
      .NonNegative("sigma_yaw_floor_rad", sigma_yaw_floor_rad)
      .Nested("search", search.Validate())
      .Nested("calibration", calibration.Validate())
      .Nested("icp", icp.Validate())
      .Nested("points", points.Validate());
  return rules.errors();
}

IcpOdometry::IcpOdometry(const IcpOdometryOptions& options)
    : options_(options), calibration_(options.calibration) {
  SLAMRIG_CHECK_VALID(options_, "IcpOdometryOptions");
}

const std::vector<Eigen::Vector2d>& IcpOdometry::local_map() const {
  static const std::vector<Eigen::Vector2d> kEmpty;
  return matcher_ ? matcher_->reference() : kEmpty;
}

Eigen::Matrix3d IcpOdometry::IncrementCovariance(const Pose2& increment) const {
  const Eigen::Vector2d sigma = options_.IncrementSigmas(increment).cwiseProduct(noise_scale_);
  return Eigen::Vector3d(sigma.x() * sigma.x(), sigma.x() * sigma.x(), sigma.y() * sigma.y())
      .asDiagonal();
}

Eigen::Vector2d IcpOdometryOptions::IncrementSigmas(const Pose2& increment) const {
  return StretchSigmas(increment.translation().norm(), std::abs(increment.theta()));
}

Eigen::Vector2d IcpOdometryOptions::StretchSigmas(double distance_m, double turn_rad) const {
  return {sigma_xy_per_m * distance_m + sigma_xy_floor_m,
          sigma_yaw_per_rad * turn_rad + sigma_yaw_per_m * distance_m + sigma_yaw_floor_rad};
}

void IcpOdometry::MeasureNoise(const Pose2& prior, const Pose2& matched, const Pose2& increment) {
  const double rate = options_.search.adapt_rate;
  if (rate <= 0.0) return;
  const Pose2 correction = prior.Between(matched);
  const Eigen::Vector2d sigma = options_.IncrementSigmas(increment);
  // The corrections' sizes in units of the model's sigma (per axis in x and y: a 2D Gaussian's
  // distance has mean sigma sqrt(pi / 2)), averaged: a mean of sizes, not of squares, so that a
  // rare wrong match moves it little; each clipped to the current search window for the same
  // reason. For Gaussian noise the mean size is sigma sqrt(2 / pi).
  const double window = std::max(options_.search.sigmas, 1.0);
  const Eigen::Vector2d size(
      correction.translation().norm() / (sigma.x() * std::sqrt(std::numbers::pi / 2.0)),
      std::abs(correction.theta()) / (sigma.y() * std::sqrt(2.0 / std::numbers::pi)));
  for (int i = 0; i < 2; ++i) {
    noise_mean_size_[i] =
        (1.0 - rate) * noise_mean_size_[i] + rate * std::min(size[i], window * noise_scale_[i]);
    noise_scale_[i] = std::max(1.0, noise_mean_size_[i]);
  }
}

Eigen::Vector2d IcpOdometry::SearchWindow(const Pose2& increment) const {
  const IcpOdometrySearchOptions& o = options_.search;
  const Eigen::Vector2d sigma = StretchNoise(increment);
  return {std::min(o.max_window_m, o.sigmas * sigma.x()),
          std::min(o.max_window_rad, o.sigmas * sigma.y())};
}

bool IcpOdometry::HoldsMapWhileBlind(const Pose2& increment) const {
  const IcpOdometrySearchOptions& o = options_.search;
  if (blind_scans_ >= o.blind_scans || o.sigmas <= 0.0) return false;
  return o.sigmas * StretchNoise(increment).x() < o.max_window_m;
}

Eigen::Vector2d IcpOdometry::StretchNoise(const Pose2& increment) const {
  // Sigmas summed over the stretch, not added in quadrature: a blind step's error is one draw,
  // not averaged out by the next, and the window stays conservative.
  return options_
      .StretchSigmas(blind_distance_m_ + increment.translation().norm(),
                     blind_turn_rad_ + std::abs(increment.theta()))
      .cwiseProduct(noise_scale_);
}

std::optional<MatchResult> IcpOdometry::SearchedMatch(const std::vector<Eigen::Vector2d>& points,
                                                      const Pose2& prior,
                                                      const Eigen::Vector2d& model_window,
                                                      std::optional<MatchResult> from_prior) {
  const IcpOdometrySearchOptions& o = options_.search;
  if (o.sigmas <= 0.0) return from_prior;
  // Below the trigger the prior is left to ICP: a correction beyond a window of centimetres, or a
  // failed match there, is ICP's own scatter or a scan too poor to match more often than a wrong
  // prior (searching wide there cost a long corridor's log 0.14 m, and a log without odometry
  // 0.7 m; docs/studies/front-end-search.md).
  const bool above_trigger =
      model_window.x() > o.trigger_window_m || model_window.y() > o.trigger_window_rad;
  if (from_prior && !above_trigger) return from_prior;
  ++counts_.searched;
  // ICP from the prior failed, or it moved the prior farther than the window (by more than a
  // raster cell or a yaw step): the prior is farther off than the noise model says (an odometry
  // that under-reports a turn puts the truth outside a window drawn around the reported turn, and
  // ICP from there finds a neighbouring minimum). The search then runs over the wide window.
  const double yaw_step = o.resolution_m / 10.0;
  auto beyond_window = [&](const MatchResult& match) {
    const Pose2 correction = prior.Between(match.pose);
    return correction.translation().norm() > model_window.x() + o.resolution_m ||
           std::abs(correction.theta()) > model_window.y() + yaw_step;
  };
  const bool doubted = above_trigger && (!from_prior || beyond_window(*from_prior));
  const Eigen::Vector2d window =
      doubted ? model_window.cwiseMax(Eigen::Vector2d(o.wide_window_m, o.wide_window_rad))
              : model_window;
  counts_.widened += doubted ? 1 : 0;
  if (!raster_) raster_ = RasterOf(matcher_->reference(), o.resolution_m, o.blur_m);
  const std::vector<Eigen::Vector2d> query = Thinned(points, o.resolution_m);
  // The yaw step: a point 10 m out moves one raster cell; ICP takes the rest.
  const CorrelativeMatcherOptions search{.linear_window_m = window.x(),
                                         .angular_window_rad = window.y(),
                                         .angular_step_rad = yaw_step,
                                         .branch_and_bound_depth = 5,
                                         .min_score = 0.05};
  const std::optional<MatchResult> coarse =
      CorrelativeMatcher(search, raster_->view).Match(query, prior);
  if (!coarse) return from_prior;
  std::optional<MatchResult> refined = GatedMatch(points, coarse->pose, Eigen::Vector2d::Zero());
  if (!refined) return from_prior;
  // Each match's fit to the raster less its prior penalty: the maximum a posteriori choice with the
  // raster as the log-likelihood up to scale and the prior's Gaussian (sigma = window / sigmas).
  const Eigen::Vector2d sigma = window / o.sigmas;
  auto posterior = [&](const Pose2& pose) {
    return RasterScore(*raster_, query, pose) -
           o.prior_weight * SquaredMahalanobis(prior, pose, sigma);
  };
  const double searched = posterior(refined->pose);
  if (from_prior && searched <= posterior(from_prior->pose) + o.min_gain) return from_prior;
  ++counts_.search_chosen;
  return refined;
}

std::pair<int, std::vector<KeyframeShareOf>> IcpOdometry::AddKeyframe(
    const std::vector<Eigen::Vector2d>& points_base, const Pose2& pose) {
  std::vector<Eigen::Vector2d> scan = Placed(points_base, pose);
  // The shares of the map this scan was matched against (none before the first map, none for
  // point-to-point ICP).
  std::vector<KeyframeShareOf> shares;
  if (matcher_ && matcher_->has_normals() && !matcher_->reference().empty()) {
    const std::vector<Eigen::Matrix3d> weights = FrameWeights(KeyframeInformations(
        map_, *matcher_, static_cast<int>(keyframes_.size()), scan, pose.translation()));
    for (std::size_t j = 0; j < keyframes_.size(); ++j) {
      shares.push_back({.id = keyframes_[j].id, .share = weights[j]});
    }
  }

  keyframes_.push_back({.id = next_keyframe_id_++, .points = std::move(scan)});
  while (static_cast<int>(keyframes_.size()) > options_.local_map_keyframes) keyframes_.pop_front();
  // Newest first, so the thinning keeps the newest point of each voxel.
  std::vector<std::vector<Eigen::Vector2d>> points;
  points.reserve(keyframes_.size());
  for (const Keyframe& k : keyframes_) points.push_back(k.points);
  map_ = ComposeLocalMap(points, options_.local_map_voxel_m);
  matcher_.emplace(options_.icp, map_.points);
  raster_.reset();
  last_keyframe_ = pose;
  return {keyframes_.back().id, std::move(shares)};
}

void IcpOdometry::JoinHeldScans() {
  for (const HeldScan& held : held_) AddKeyframe(held.points_base, held.pose);
  held_.clear();
}

std::optional<MatchResult> IcpOdometry::EndBlindStretch(const std::vector<Eigen::Vector2d>& points,
                                                        const Pose2& prior, const Pose2& increment,
                                                        std::optional<MatchResult> held_map_match) {
  // The map as it would be had the held scans joined it (newest first, as AddKeyframe composes).
  std::vector<std::vector<Eigen::Vector2d>> newest_first;
  for (auto it = held_.rbegin(); it != held_.rend(); ++it) {
    newest_first.push_back(Placed(it->points_base, it->pose));
  }
  for (auto it = keyframes_.rbegin();
       it != keyframes_.rend() &&
       static_cast<int>(newest_first.size()) < options_.local_map_keyframes;
       ++it) {
    newest_first.push_back(it->points);
  }
  const LocalMapPoints joined = ComposeLocalMap(newest_first, options_.local_map_voxel_m);
  // ICP from the prior over the increment's own window, as the scan would have been matched.
  std::optional<MatchResult> with_held =
      IcpMatcher(options_.icp, joined.points).Match(points, prior);
  const Eigen::Vector2d own_window =
      options_.search.sigmas * options_.IncrementSigmas(increment).cwiseProduct(noise_scale_);
  if (with_held && !WithinGates(*with_held, prior, own_window)) with_held.reset();
  // The better score wins; where the two are within search.min_gain the scores cannot tell, and
  // the prior decides: each match's score less its prior penalty, as the search chooses
  // (SearchedMatch). A held-map match turned far beyond the stretch's own noise, scoring no better,
  // is a map without the failed scan's view, not a wheel error taken back.
  auto posterior = [&](const MatchResult& match, const Eigen::Vector2d& window) {
    return match.score - options_.search.prior_weight *
                             SquaredMahalanobis(prior, match.pose, window / options_.search.sigmas);
  };
  auto with_held_wins = [&] {
    if (!held_map_match) return true;
    const double gain = with_held->score - held_map_match->score;
    if (std::abs(gain) > options_.search.min_gain) return gain > 0.0;
    return posterior(*with_held, own_window) > posterior(*held_map_match, SearchWindow(increment));
  };
  if (with_held && with_held_wins()) {
    JoinHeldScans();
    return with_held;
  }
  if (held_map_match) held_.clear();  // the held map placed the scan: the held scans go
  return held_map_match;
}

void IcpOdometry::Count(IcpOdometryOutcome outcome) {
  switch (outcome) {
    case IcpOdometryOutcome::kMatched:
      ++counts_.matched;
      break;
    case IcpOdometryOutcome::kDegenerate:
      ++counts_.degenerate;
      break;
    case IcpOdometryOutcome::kMatchFailed:
      ++counts_.failed;
      break;
    case IcpOdometryOutcome::kNoPoints:
      ++counts_.no_points;
      break;
    case IcpOdometryOutcome::kFirstScan:
      break;
  }
}

bool IcpOdometry::HoldIfBlind(IcpOdometryOutcome outcome,
                              const std::vector<Eigen::Vector2d>& points, const Pose2& increment,
                              bool after_gap) {
  // A scan the wheels placed alone stays out of the local map while the stretch is searchable.
  const bool blind =
      outcome == IcpOdometryOutcome::kMatchFailed || outcome == IcpOdometryOutcome::kNoPoints;
  const bool held = blind && matcher_ && !after_gap && HoldsMapWhileBlind(increment);
  if (held) {
    if (!points.empty()) held_.push_back({.points_base = points, .pose = pose_});
    ++blind_scans_;
    blind_distance_m_ += increment.translation().norm();
    blind_turn_rad_ += std::abs(increment.theta());
  } else {
    JoinHeldScans();  // a stretch that ends blind keeps the wheels' placement
    blind_scans_ = 0;
    blind_distance_m_ = 0.0;
    blind_turn_rad_ = 0.0;
  }
  return held;
}

IcpOdometryStep IcpOdometry::Add(const LaserScan& scan, const Pose2& odometry_increment,
                                 double odometry_gap_s) {
  return Add(scan, std::vector<Pose2>{odometry_increment}, odometry_gap_s);
}

bool IcpOdometry::WithinGates(const MatchResult& match, const Pose2& prior,
                              const Eigen::Vector2d& window) const {
  return match.score >= options_.min_score &&
         (match.pose.translation() - prior.translation()).norm() <=
             std::max(options_.max_correction_m, window.x()) &&
         std::abs(NormalizeAngle(match.pose.theta() - prior.theta())) <=
             std::max(options_.max_correction_rad, window.y());
}

std::optional<MatchResult> IcpOdometry::GatedMatch(const std::vector<Eigen::Vector2d>& points,
                                                   const Pose2& prior,
                                                   const Eigen::Vector2d& window) const {
  std::optional<MatchResult> match = matcher_->Match(points, prior);
  if (match && !WithinGates(*match, prior, window)) match.reset();
  return match;
}

Eigen::Vector2d IcpOdometry::KeptCorrection(const MatchResult& match, const Pose2& fallback,
                                            const Eigen::Matrix3d& prior_covariance,
                                            const std::vector<Eigen::Vector2d>& points,
                                            bool* degenerate) const {
  // Keep the (calibrated) odometry along poorly constrained directions of the match ...
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(match.covariance.topLeftCorner<2, 2>());
  Eigen::Vector2d correction = match.pose.translation() - fallback.translation();
  const double max_var = options_.max_translation_stddev_m * options_.max_translation_stddev_m;
  for (int i = 0; i < 2; ++i) {
    const double variance = eig.eigenvalues()[i];
    if (variance > max_var ||
        variance > options_.max_covariance_ratio * std::max(eig.eigenvalues()[0], 1e-300)) {
      const Eigen::Vector2d e = eig.eigenvectors().col(i);
      correction -= e.dot(correction) * e;
      *degenerate = true;
    }
  }
  // ... and along a direction the scan itself hardly sees, where the match moved far from the
  // odometry (IcpOdometryOptions::weak_direction_ratio).
  if (options_.weak_direction_ratio > 0.0) {
    const MatchConstraints geometry = ScanGeometry(points);
    const Eigen::Matrix2d to_odom = Eigen::Rotation2Dd(match.pose.theta()).toRotationMatrix();
    const double gate = options_.weak_direction_gate_sigmas * std::sqrt(prior_covariance(0, 0));
    for (int i = 0; i < 2; ++i) {
      if (geometry.eigenvalues[i] >= options_.weak_direction_ratio * geometry.eigenvalues.y())
        continue;
      const Eigen::Vector2d e = to_odom * geometry.eigenvectors.col(i);
      if (std::abs(e.dot(correction)) <= gate) continue;
      correction -= e.dot(correction) * e;
      *degenerate = true;
    }
  }
  return correction;
}

IcpOdometryStep IcpOdometry::Add(const LaserScan& scan, const std::vector<Pose2>& increments,
                                 double odometry_gap_s) {
  SLAMRIG_CHECK(!increments.empty(), "IcpOdometry::Add: no increment");
  const std::vector<Eigen::Vector2d> points = ScanToBasePoints(scan, options_.points);
  ++counts_.scans;
  IcpOdometryStep step;
  if (!started_) {
    started_ = true;
    step.pose = pose_;
    step.outcome = IcpOdometryOutcome::kFirstScan;
    if (!points.empty()) {
      step.keyframe_id = AddKeyframe(points, pose_).first;
      step.keyframe = true;
    }
    return step;
  }

  // The match from each increment, the first (the prediction) the prior: another seed's match
  // replaces the prediction's only when it scores better by search.min_gain (where the scan
  // cannot tell, along a corridor, the prediction stands, not the seed that overlaps the map
  // best, which is standing still), and the search and the degenerate directions keep to it.
  std::optional<MatchResult> match;
  const Pose2& odometry_increment = increments.front();
  // After a gap the increment says nothing: the widest window, every heading.
  const bool after_gap = options_.search.gap_s > 0.0 && odometry_gap_s > options_.search.gap_s;
  auto window_of = [&](const Pose2& increment) {
    return after_gap ? Eigen::Vector2d(options_.search.max_window_m, std::numbers::pi)
                     : SearchWindow(increment);
  };
  if (!points.empty() && matcher_) {
    for (std::size_t i = 0; i < increments.size(); ++i) {
      std::optional<MatchResult> m =
          GatedMatch(points, pose_ * increments[i], window_of(increments[i]));
      const double margin = match && i > 0 ? options_.search.min_gain : 0.0;
      if (m && (!match || m->score > match->score + margin)) match = std::move(m);
    }
  }
  const Pose2 prior = pose_ * odometry_increment;
  // Where the odometry stands in for the scan, it does so with its fitted drift taken out.
  const Pose2 fallback = pose_ * calibration_.Correct(odometry_increment);
  // The increment's noise, rotated from the previous base frame into the odom frame.
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(pose_.theta()).toRotationMatrix();
  Eigen::Matrix3d prior_covariance = IncrementCovariance(odometry_increment);
  prior_covariance.topLeftCorner<2, 2>() =
      r * prior_covariance.topLeftCorner<2, 2>() * r.transpose();
  step.pose = fallback;
  step.prior = prior;
  step.window = window_of(odometry_increment);
  step.covariance = prior_covariance;
  if (!points.empty() && matcher_) {
    const IcpOdometryCounts before = counts_;
    match = SearchedMatch(points, prior, step.window, std::move(match));
    if (!held_.empty())
      match = EndBlindStretch(points, prior, odometry_increment, std::move(match));
    step.searched = counts_.searched > before.searched;
    step.search_chosen = counts_.search_chosen > before.search_chosen;
    step.search_widened = counts_.widened > before.widened;
  }

  // Failed unless the match below says otherwise (also with no local map yet).
  step.outcome = points.empty() ? IcpOdometryOutcome::kNoPoints : IcpOdometryOutcome::kMatchFailed;

  if (match) {
    bool degenerate = false;
    const Eigen::Vector2d correction =
        KeptCorrection(*match, fallback, prior_covariance, points, &degenerate);
    double yaw = match->pose.theta();
    if (match->covariance(2, 2) > options_.max_yaw_stddev_rad * options_.max_yaw_stddev_rad) {
      yaw = fallback.theta();
      degenerate = true;
    }
    step.pose = Pose2(fallback.x() + correction.x(), fallback.y() + correction.y(), yaw);
    step.covariance = match->covariance;
    step.score = match->score;
    step.outcome = degenerate ? IcpOdometryOutcome::kDegenerate : IcpOdometryOutcome::kMatched;
    // After a blind stretch the correction is the stretch's, not this increment's alone.
    const bool after_blind = blind_scans_ > 0;
    if (!degenerate && !after_gap && !after_blind) {
      MeasureNoise(prior, step.pose, odometry_increment);
    }
  }
  Count(step.outcome);

  // The drift is fitted from clear matches following clear matches: the increment between them
  // is the scans' own, not a correction of what a blind stretch let accumulate.
  if (step.outcome == IcpOdometryOutcome::kMatched && last_matched_ && !after_gap) {
    calibration_.Observe(odometry_increment, pose_.Inverse() * step.pose);
  }
  last_matched_ = step.outcome == IcpOdometryOutcome::kMatched;
  pose_ = step.pose;
  const bool held = HoldIfBlind(step.outcome, points, odometry_increment, after_gap);
  const Pose2 since = last_keyframe_.Between(pose_);
  if (!held && !points.empty() &&
      (!matcher_ || since.translation().norm() >= options_.keyframe_distance_m ||
       std::abs(since.theta()) >= options_.keyframe_angle_rad)) {
    std::tie(step.keyframe_id, step.frame_weights) = AddKeyframe(points, pose_);
    step.keyframe = true;
  }
  return step;
}

}  // namespace slamrig::slam
