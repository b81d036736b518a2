// Rao-Blackwellised particle filter SLAM after Grisetti, Stachniss, Burgard, "Improved Techniques
// for Grid Mapping with Rao-Blackwellized Particle Filters", IEEE T-RO 23(1), 2007:
//  - proposal: scan-match each particle against its own map from the odometry prediction
//    (Table I, step "scan-matching"); sample K poses around the match, x_j, and weigh each by
//    p(z | m, x_j) p(x_j | x_{t-1}, u) (Eqs. 15-16); their weighted mean and covariance define the
//    Gaussian the new pose is drawn from (Eq. 17);
//  - weight: multiplied by the normaliser eta, the sum of those weights (Eq. 18); a failed match
//    samples the odometry model and weighs by the likelihood alone;
//  - selective resampling when Neff < N/2 (Sec. V); the maps are copy-on-write TiledGrids.
#include "slam/pf/rbpf.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "slam/pf/particle_filter.h"
#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// A prior's standard deviation that leaves the climb free along it.
constexpr double kNoPrior = 1e6;
// Updates before the long-term matched fraction is a level to judge a match against.
constexpr int kLevelWarmupUpdates = 20;
// A match below this share of the long-term matched fraction is a poor one: it does not lower
// that level, and it sends the map check searching.
constexpr double kPoorMatchShare = 0.5;
// The alias search and the map check rank their grid twice as coarse as the gap search's in
// position and in heading: an eighth of its cost over four times its area.
constexpr int kSearchCoarsening = 2;

// About 48 of `points`, spread along the scan: ranks a grid of poses, for a climb from the best,
// at a fraction of every point's cost.
std::vector<MatchPoint> SpreadSubset(const std::vector<MatchPoint>& points) {
  constexpr std::size_t kGridPoints = 48;
  std::vector<MatchPoint> sparse;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / kGridPoints);
  for (std::size_t i = 0; i < points.size(); i += stride) sparse.push_back(points[i]);
  return sparse;
}

// Of the points at `pose` with no wall (a cell of positive log-odds) within a cell of their hit,
// the share whose hit cell the map has seen free (negative log-odds) rather than never seen; 0
// when every point finds a wall.
double SeenFreeShare(const TiledGrid& map, const std::vector<MatchPoint>& points,
                     const Pose2& pose) {
  int unmatched = 0;
  int seen_free = 0;
  for (const MatchPoint& p : points) {
    const Eigen::Array2i cell = map.WorldToCell(pose * p.hit);
    bool wall = false;
    for (int dy = -1; dy <= 1 && !wall; ++dy) {
      for (int dx = -1; dx <= 1 && !wall; ++dx)
        wall = map.LogOdds(cell.x() + dx, cell.y() + dy) > 0.0f;
    }
    if (wall) continue;
    ++unmatched;
    seen_free += map.LogOdds(cell) < 0.0f;
  }
  return unmatched == 0 ? 0.0 : static_cast<double>(seen_free) / unmatched;
}

}  // namespace

double RingOffsetRms(const Pose2& a, const Pose2& b, double radius_m) {
  const double squared = (a.translation() - b.translation()).squaredNorm() +
                         2.0 * (1.0 - std::cos(a.theta() - b.theta())) * radius_m * radius_m;
  return std::sqrt(squared);
}

RbpfPoseNode::~RbpfPoseNode() {
  std::shared_ptr<RbpfPoseNode> next = std::move(parent);
  while (next && next.use_count() == 1) next = std::move(next->parent);
}

Rbpf::Rbpf(const RbpfOptions& options)
    : options_(options), matcher_(options.matcher), rng_(options.seed) {
  SLAMRIG_CHECK_VALID(options_, "RbpfOptions");
  if (const int threads = ThreadCount(options_.num_threads); threads > 1) {
    pool_ = std::make_unique<ThreadPool>(threads);
  }
}

void Rbpf::UpdateParticle(RbpfParticle& particle, const ScanUpdate& update, std::uint64_t seed,
                          bool* failed) const {
  RandomEngine rng(seed);
  const Pose2& motion = update.motion;
  const std::vector<MatchPoint>& points = *update.points;
  const Pose2 predicted = particle.pose * motion;
  // Not a structured binding: clang 14 (the fuzz build) refuses one captured by a lambda.
  const std::pair<double, double> sigmas = MotionSigmas(motion);
  const double sigma_xy = sigmas.first;
  const double sigma_yaw = sigmas.second;
  const double scale = options_.observation_scale;

  // The climb starts from a draw of the motion model, not from the prediction itself (as the
  // gmapping code does): the matcher sees only a few cells around each point, so the spread of
  // starting points is what lets some particles reach the right match after a large odometry
  // error. The motion prior below stays centred on the prediction.
  const Eigen::Vector3d start_noise = StandardNormal3(rng);
  const Pose2 start = predicted * Pose2(sigma_xy * start_noise.x(), sigma_xy * start_noise.y(),
                                        sigma_yaw * start_noise.z());
  const ClimbResult match =
      matcher_.Climb(particle.map, points, start, PosePrior{predicted, sigma_xy, sigma_yaw});
  // log_eta is the untempered normaliser (the path's likelihood); log_eta_weight the one the
  // weight takes: per point tempered (weight_correlation_per_point), else log_eta.
  const bool per_point = options_.weight_correlation_per_point;
  double log_eta = 0.0;
  double log_eta_weight = 0.0;
  Pose2 drawn;
  if (points.empty() || match.fit.matched < options_.matcher.min_matched_fraction *
                                                static_cast<double>(points.size())) {
    // No usable match: the odometry model is the proposal, the likelihood the weight.
    *failed = true;
    drawn = start;
    const MatchFit fit = matcher_.Evaluate(particle.map, points, drawn);
    log_eta = scale * fit.log_likelihood;
    log_eta_weight = per_point ? scale * fit.weighted_log_likelihood : log_eta;
  } else {
    // K = 27 poses on a grid around the match, weighted by likelihood times motion prior.
    constexpr int kSamples = 27;
    std::array<Eigen::Vector3d, kSamples> offsets;
    std::array<double, kSamples> log_q;
    std::array<double, kSamples> log_q_weight;
    int j = 0;
    for (int iy = -1; iy <= 1; ++iy) {
      for (int ix = -1; ix <= 1; ++ix) {
        for (int it = -1; it <= 1; ++it, ++j) {
          offsets[j] =
              Eigen::Vector3d(ix * options_.proposal_xy_step_m, iy * options_.proposal_xy_step_m,
                              it * options_.proposal_yaw_step_rad);
          const Pose2 x(match.pose.x() + offsets[j].x(), match.pose.y() + offsets[j].y(),
                        match.pose.theta() + offsets[j].z());
          const Pose2 e = predicted.Between(x);
          const double log_prior = -0.5 * ((e.x() * e.x() + e.y() * e.y()) / (sigma_xy * sigma_xy) +
                                           e.theta() * e.theta() / (sigma_yaw * sigma_yaw));
          const MatchFit fit = matcher_.Evaluate(particle.map, points, x);
          log_q[j] = scale * fit.log_likelihood + log_prior;
          log_q_weight[j] = scale * fit.weighted_log_likelihood + log_prior;
        }
      }
    }
    const double max_log_q = *std::max_element(log_q.begin(), log_q.end());
    double sum = 0.0;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    std::array<double, kSamples> w;
    for (int k = 0; k < kSamples; ++k) {
      w[k] = std::exp(log_q[k] - max_log_q);
      sum += w[k];
      mean += w[k] * offsets[k];
    }
    mean /= sum;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (int k = 0; k < kSamples; ++k) {
      const Eigen::Vector3d d = offsets[k] - mean;
      covariance += (w[k] / sum) * d * d.transpose();
    }
    // The mean of the sample weights (not their sum) keeps eta on the scale of a failed match's
    // single likelihood.
    log_eta = max_log_q + std::log(sum / kSamples);
    log_eta_weight = log_eta;
    if (per_point) {
      const double max_log_qw = *std::max_element(log_q_weight.begin(), log_q_weight.end());
      double sum_w = 0.0;
      for (const double q : log_q_weight) sum_w += std::exp(q - max_log_qw);
      log_eta_weight = max_log_qw + std::log(sum_w / kSamples);
    }
    covariance.diagonal().array() += 1e-12;
    const Eigen::Matrix3d l = covariance.llt().matrixL();
    const Eigen::Vector3d z = StandardNormal3(rng);
    const Eigen::Vector3d d = mean + options_.proposal_spread * Eigen::Vector3d(l * z);
    drawn = Pose2(match.pose.x() + d.x(), match.pose.y() + d.y(), match.pose.theta() + d.z());
  }
  particle.pose = drawn;
  particle.log_weight += update.weight_exponent * log_eta_weight;
  particle.path_log_likelihood += log_eta;
  particle.map.InsertScan(*update.scan, drawn, update.map_range_m);
  particle.history = std::make_shared<RbpfPoseNode>(drawn, std::move(particle.history));
}

double Rbpf::WeightExponent(const std::vector<MatchPoint>& points) const {
  const double length = options_.weight_correlation_length_m;
  if (!(length > 0.0) || points.empty() || options_.weight_correlation_per_point) {
    return options_.weight_exponent;
  }
  // The same factor for every particle (the points are in the base frame): it rescales every
  // log-weight increment alike, so the particles' order by weight is unchanged.
  const double independent = CountIndependentPoints(points, length);
  return options_.weight_exponent * std::min(1.0, independent / static_cast<double>(points.size()));
}

std::pair<double, double> Rbpf::MotionSigmas(const Pose2& motion) const {
  const RbpfMotionNoise& noise = options_.motion;
  const double trans = motion.translation().norm();
  const double rot = std::abs(motion.theta());
  return {noise.xy_per_m * trans + noise.xy_per_rad * rot + noise.min_xy_m,
          noise.yaw_per_m * trans + noise.yaw_per_rad * rot + noise.min_yaw_rad};
}

Pose2 Rbpf::CheckOdometry(const Pose2& motion, const std::vector<MatchPoint>& points,
                          bool* rejected, ClimbResult* near_out) const {
  // Hypotheses for the increment, compared on the best particle's map (the increment is in the
  // robot frame, so it carries over to every particle):
  //  - the odometry holds: the match near the prediction, climbed with the motion prior, whose
  //    density is (1 - eps) times the Gaussian motion model;
  //  - the odometry's translation failed: the best match anywhere in the window, whose
  //    translation density is eps / window area (yaw still from the Gaussian: slip and a
  //    reversal counted as forward motion are failures of the translation);
  //  - with odometry_turn_check, its turn failed: below.
  // Each is scored by its observation likelihood (observation_scale, untempered: tempered like
  // the weights, the check misses reversals counted as forward motion) times that density.
  // Without a failure the window's best match is the prediction's or one the density ratio
  // outweighs (a corridor's axis gives equal likelihoods: the odometry wins there).
  *rejected = false;
  const RbpfParticle& best = particles_[best_];
  const Pose2 predicted = best.pose * motion;
  // Not a structured binding: clang 14 (the fuzz build) refuses one captured by a lambda.
  const std::pair<double, double> sigmas = MotionSigmas(motion);
  const double sigma_xy = sigmas.first;
  const double sigma_yaw = sigmas.second;
  const double scale = options_.observation_scale;
  const double eps = options_.odometry_failure_probability;
  constexpr double kLog2Pi = 1.8378770664093453;
  auto log_yaw_density = [&](const Pose2& pose) {
    const double dt = NormalizeAngle(pose.theta() - predicted.theta());
    return -0.5 * dt * dt / (sigma_yaw * sigma_yaw) - 0.5 * kLog2Pi - std::log(sigma_yaw);
  };

  const ClimbResult near =
      matcher_.Climb(best.map, points, predicted, PosePrior{predicted, sigma_xy, sigma_yaw});
  if (near_out != nullptr) *near_out = near;
  const double ex = near.pose.x() - predicted.x();
  const double ey = near.pose.y() - predicted.y();
  const double log_near = scale * matcher_.Evaluate(best.map, points, near.pose).log_likelihood +
                          std::log1p(-eps) - 0.5 * (ex * ex + ey * ey) / (sigma_xy * sigma_xy) -
                          kLog2Pi - 2.0 * std::log(sigma_xy) + log_yaw_density(near.pose);

  Pose2 chosen = near.pose;
  double log_chosen = log_near;
  const double half =
      options_.odometry_window_per_m * motion.translation().norm() + options_.odometry_window_min_m;
  const double step = options_.odometry_window_step_m;
  const int n = static_cast<int>(std::ceil(half / step));
  const double log_far_density = std::log(eps) - 2.0 * std::log(2.0 * n * step);
  // A point's log-likelihood is at most 0: where even a perfect match in the window could not
  // beat the match near the prediction, the window need not be searched.
  if (log_far_density + log_yaw_density(predicted) > log_chosen) {
    // No prior on the position: under this hypothesis the odometry says nothing about it.
    double far_ll = 0.0;
    const Pose2 far = BestAtAnyHeading(best.map, points, predicted, half, 0.0,
                                       PosePrior{predicted, kNoPrior, sigma_yaw}, &far_ll, nullptr);
    const Pose2 remapped = RemapDegenerate(best.map, points, near.pose, far);
    const double log_far = scale * matcher_.Evaluate(best.map, points, remapped).log_likelihood +
                           log_far_density + log_yaw_density(remapped);
    if (log_far > log_chosen) {
      chosen = remapped;
      log_chosen = log_far;
      *rejected = true;
    }
  }
  // The wheels' turn failed (odometry_turn_check: a turn on the spot they missed, a burst of
  // heading noise): the heading is anywhere within a quarter turn of the prediction (eps / pi),
  // the position still the Gaussian's. Searched only where a perfect match at the Gaussian's peak
  // could beat the best so far.
  constexpr double kTurnFailureRad = std::numbers::pi / 2.0;
  const double log_turn_density =
      std::log(eps) - std::log(2.0 * kTurnFailureRad) - kLog2Pi - 2.0 * std::log(sigma_xy);
  if (options_.odometry_turn_check && log_turn_density > log_chosen) {
    double ll = 0.0;
    double other = 0.0;
    const Pose2 turned =
        BestAtAnyHeading(best.map, points, predicted, std::max(2.0 * sigma_xy, step),
                         kTurnFailureRad, PosePrior{predicted, sigma_xy, kNoPrior}, &ll, &other);
    const double tx = turned.x() - predicted.x();
    const double ty = turned.y() - predicted.y();
    const double log_turn =
        scale * ll + log_turn_density - 0.5 * (tx * tx + ty * ty) / (sigma_xy * sigma_xy);
    // The same pose as the odometry's own (Gaussian) hypothesis would have it: a heading within
    // the Gaussian's reach is a better match the climb from the prediction missed, not a failed
    // turn, and the particles' own climbs are left to find it.
    const double log_as_near = log_turn - log_turn_density + std::log1p(-eps) - kLog2Pi -
                               2.0 * std::log(sigma_xy) + log_yaw_density(turned);
    // Only a heading the scan picks out: where another heading matches nearly as well (a
    // corridor seen from either end, a symmetric room), the scan cannot overrule the wheels.
    const bool unique = scale * (ll - other) > std::log((1.0 - eps) / eps);
    if (unique && log_turn > log_as_near && log_turn > log_chosen) {
      chosen = turned;
      *rejected = true;
    }
  }
  return *rejected ? best.pose.Between(chosen) : motion;
}

double Rbpf::MatchedFraction(const TiledGrid& map, const std::vector<MatchPoint>& points,
                             const Pose2& pose) const {
  return points.empty() ? 0.0
                        : static_cast<double>(matcher_.Evaluate(map, points, pose).matched) /
                              static_cast<double>(points.size());
}

std::optional<Pose2> Rbpf::PlaceInMap(const TiledGrid& map, const std::vector<MatchPoint>& points,
                                      const Pose2& center, double half_m, double yaw_half_rad,
                                      double near_fraction) const {
  double ll = 0.0;
  double other_ll = 0.0;
  const Pose2 far =
      BestAtAnyHeading(map, points, center, half_m, yaw_half_rad,
                       PosePrior{center, kNoPrior, kNoPrior}, &ll, &other_ll, kSearchCoarsening);
  const double far_fraction = MatchedFraction(map, points, far);
  // Only a place the scan picks out: where another heading matches within the odds of a failed
  // increment (the turn check's rule), the poor match is more likely new ground than an alias.
  const double eps = options_.odometry_failure_probability;
  const bool unique = options_.observation_scale * (ll - other_ll) > std::log((1.0 - eps) / eps);
  if (!unique || far_fraction < options_.scan_matched_accept_ratio * matched_level_ ||
      !(far_fraction > near_fraction + options_.scan_matched_win_margin * matched_level_)) {
    return std::nullopt;
  }
  return far;
}

ClimbResult Rbpf::NearClimb(const Pose2& motion, const std::vector<MatchPoint>& points,
                            const std::optional<ClimbResult>& climbed) const {
  if (climbed) return *climbed;
  const RbpfParticle& best = particles_[best_];
  const Pose2 predicted = best.pose * motion;
  const auto [sigma_xy, sigma_yaw] = MotionSigmas(motion);
  return matcher_.Climb(best.map, points, predicted, PosePrior{predicted, sigma_xy, sigma_yaw});
}

Pose2 Rbpf::SearchScanMatchedAlias(const Pose2& motion, const std::vector<MatchPoint>& points,
                                   const std::optional<ClimbResult>& climbed, bool* moved) const {
  *moved = false;
  if (matched_samples_ < kLevelWarmupUpdates) return motion;
  const RbpfParticle& best = particles_[best_];
  const Pose2 predicted = best.pose * motion;
  const ClimbResult near = NearClimb(motion, points, climbed);
  const double near_fraction = MatchedFraction(best.map, points, near.pose);
  if (near_fraction >= options_.scan_matched_accept_ratio * matched_level_) return motion;
  const std::optional<Pose2> far = PlaceInMap(
      best.map, points, predicted, options_.scan_matched_window_m, std::numbers::pi, near_fraction);
  if (!far) return motion;
  *moved = true;
  return best.pose.Between(*far);
}

std::optional<Rbpf::MapCheck> Rbpf::StartMapCheck(const Pose2& motion,
                                                  const std::vector<MatchPoint>& points,
                                                  const std::optional<ClimbResult>& climbed) const {
  if (options_.map_check_window_m <= 0.0 || options_.odometry_failure_probability <= 0.0 ||
      matched_samples_ < kLevelWarmupUpdates || points.empty()) {
    return std::nullopt;
  }
  const RbpfParticle& best = particles_[best_];
  const Pose2 predicted = best.pose * motion;
  const ClimbResult near = NearClimb(motion, points, climbed);
  const double near_fraction = MatchedFraction(best.map, points, near.pose);
  if (!(near_fraction < kPoorMatchShare * matched_level_)) return std::nullopt;
  // New ground is no contradiction: only where most of the points that find no wall land on
  // cells the map has seen free does the map say the robot is not there.
  if (!(SeenFreeShare(best.map, points, near.pose) > 0.5)) return std::nullopt;
  // A copy shares the map's tiles: the particles write theirs, this one keeps the map as it was.
  return MapCheck{best.map, predicted, near_fraction};
}

std::optional<Pose2> Rbpf::FinishMapCheck(const MapCheck& check,
                                          const std::vector<MatchPoint>& points,
                                          const Pose2& chosen) const {
  // Where the particles found a place the map holds after all, the path agrees with it here.
  if (MatchedFraction(check.map, points, chosen) >=
      options_.scan_matched_accept_ratio * matched_level_) {
    return std::nullopt;
  }
  // Within a quarter turn of the prediction, the turn check's failed turn: further round, a
  // match is a building's symmetry (a corridor seen from its other end), not the wheels' error.
  return PlaceInMap(check.map, points, check.predicted, options_.map_check_window_m,
                    std::numbers::pi / 2.0, check.near_fraction);
}

Pose2 Rbpf::ChooseMotion(const Pose2& pending, bool after_gap,
                         const std::vector<MatchPoint>& points, bool* rejected,
                         std::optional<ClimbResult>* near_climb_out) {
  near_climb_out->reset();
  if (points.empty()) return pending;
  Pose2 motion = pending;
  std::optional<ClimbResult> near_climb;  // the best particle's climb from `motion`'s prediction
  if (after_gap) {
    bool moved = false;
    motion = SearchAfterGap(pending, points, &moved);
    gap_corrections_ += moved;
  } else if (options_.odometry_failure_probability > 0.0) {
    ClimbResult near;
    motion = CheckOdometry(pending, points, rejected, &near);
    odometry_rejections_ += *rejected;
    // Kept, the increment's climb is the one the alias search starts from.
    if (!*rejected) near_climb = near;
  }
  if (!after_gap && scan_matched_increments_ && options_.scan_matched_window_m > 0.0 &&
      options_.odometry_failure_probability > 0.0) {
    bool moved = false;
    motion = SearchScanMatchedAlias(motion, points, near_climb, &moved);
    gap_corrections_ += moved;
    *rejected = *rejected || moved;
    if (moved) near_climb.reset();
  }
  *near_climb_out = near_climb;
  return motion;
}

Pose2 Rbpf::SearchAfterGap(const Pose2& motion, const std::vector<MatchPoint>& points,
                           bool* moved) const {
  // The increment is unknown over the gap: no motion prior on either hypothesis, only the scan's
  // likelihood on the best particle's map.
  const RbpfParticle& best = particles_[best_];
  const Pose2 predicted = best.pose * motion;
  const PosePrior no_prior{predicted, kNoPrior, kNoPrior};
  const ClimbResult near = matcher_.Climb(best.map, points, predicted, no_prior);
  const double log_near = matcher_.Evaluate(best.map, points, near.pose).log_likelihood;
  double log_far = -std::numeric_limits<double>::infinity();
  const Pose2 far_pose =
      BestAtAnyHeading(best.map, points, predicted, options_.odometry_gap_window_m,
                       std::numbers::pi, no_prior, &log_far, nullptr);
  *moved = log_far > log_near;
  return best.pose.Between(*moved ? far_pose : near.pose);
}

Pose2 Rbpf::BestAtAnyHeading(const TiledGrid& map, const std::vector<MatchPoint>& points,
                             const Pose2& center, double half_m, double yaw_half_rad,
                             const PosePrior& prior, double* log_likelihood, double* runner_up,
                             int coarsening) const {
  // The grid of headings and positions (a spread subset of the points, as in CheckOdometry)
  // picks where to climb from: the best position at each heading, and the best few headings,
  // apart from each other, are climbed (the subset of points ranks them only roughly: a room's
  // other wall may rank first).
  const double yaw_step_rad = 0.02 * coarsening;
  const std::vector<MatchPoint> sparse = SpreadSubset(points);
  const double step = options_.odometry_window_step_m * coarsening;
  const int n = static_cast<int>(std::ceil(half_m / step));
  // The whole circle from the centre's heading, or [-yaw_half_rad, yaw_half_rad) around it.
  const bool circle = yaw_half_rad >= std::numbers::pi;
  const double span = circle ? 2.0 * std::numbers::pi : 2.0 * yaw_half_rad;
  const double first = circle ? 0.0 : -yaw_half_rad;
  const int headings = std::max(1, static_cast<int>(std::ceil(span / yaw_step_rad)));
  std::vector<std::pair<double, Pose2>> per_heading;
  per_heading.reserve(static_cast<std::size_t>(headings));
  for (int k = 0; k < headings; ++k) {
    const double yaw = center.theta() + first + k * (span / headings);
    std::pair<double, Pose2> best_here{-std::numeric_limits<double>::infinity(), center};
    for (int iy = -n; iy <= n; ++iy) {
      for (int ix = -n; ix <= n; ++ix) {
        const Pose2 pose(center.x() + ix * step, center.y() + iy * step, yaw);
        const double ll = matcher_.Evaluate(map, sparse, pose).log_likelihood;
        if (ll > best_here.first) best_here = {ll, pose};
      }
    }
    per_heading.push_back(best_here);
  }
  std::stable_sort(per_heading.begin(), per_heading.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  constexpr int kStarts = 8;
  constexpr double kDistinctRad = 0.1;
  std::vector<Pose2> starts;
  for (const std::pair<double, Pose2>& ranked : per_heading) {
    // Not a structured binding: clang 14 (the fuzz build) refuses one captured by a lambda.
    const Pose2& pose = ranked.second;
    if (static_cast<int>(starts.size()) == kStarts) break;
    const bool distinct = std::none_of(starts.begin(), starts.end(), [&](const Pose2& s) {
      return std::abs(NormalizeAngle(s.theta() - pose.theta())) < kDistinctRad;
    });
    if (distinct) starts.push_back(pose);
  }
  std::vector<std::pair<double, Pose2>> climbed;
  for (const Pose2& start : starts) {
    const ClimbResult climb = matcher_.Climb(map, points, start, prior);
    climbed.emplace_back(matcher_.Evaluate(map, points, climb.pose).log_likelihood, climb.pose);
  }
  std::stable_sort(climbed.begin(), climbed.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  *log_likelihood = climbed.empty() ? -std::numeric_limits<double>::infinity() : climbed[0].first;
  if (runner_up != nullptr) {
    // The best climb at a heading apart from the best's: another peak, not its shoulder.
    constexpr double kOtherPeakRad = 0.3;
    *runner_up = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 1; k < climbed.size(); ++k) {
      if (std::abs(NormalizeAngle(climbed[k].second.theta() - climbed[0].second.theta())) >
          kOtherPeakRad) {
        *runner_up = climbed[k].first;
        break;
      }
    }
  }
  return climbed.empty() ? center : climbed[0].second;
}

Pose2 Rbpf::RemapDegenerate(const TiledGrid& map, const std::vector<MatchPoint>& points,
                            const Pose2& near, const Pose2& far) const {
  // Solution remapping after Zhang, Kaess, Singh, "On Degeneracy of Optimization-based State
  // Estimation Problems", ICRA 2016: along a direction where the scan's information (the
  // translation Hessian of its log-likelihood at the far match) is a small fraction of its
  // information along the best-determined one, the scan cannot place the robot (a corridor's
  // axis), so the far match's displacement from the near one is dropped there and the odometry
  // stands: otherwise the check moves the robot along a corridor whose far end the scan happens
  // to match a little better.
  const double ratio = options_.odometry_degenerate_ratio;
  if (ratio <= 0.0) return far;
  const double h = options_.map.resolution_m;
  auto ll = [&](double dx, double dy) {
    return matcher_.Evaluate(map, points, Pose2(far.x() + dx, far.y() + dy, far.theta()))
        .log_likelihood;
  };
  const double l0 = ll(0.0, 0.0);
  Eigen::Matrix2d information;
  information(0, 0) = -(ll(h, 0.0) - 2.0 * l0 + ll(-h, 0.0)) / (h * h);
  information(1, 1) = -(ll(0.0, h) - 2.0 * l0 + ll(0.0, -h)) / (h * h);
  information(0, 1) = information(1, 0) =
      -(ll(h, h) - ll(h, -h) - ll(-h, h) + ll(-h, -h)) / (4.0 * h * h);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(information);
  const double strongest = eigen.eigenvalues()(1);
  // Not a peak at all (the far match is on a slope or a plateau): nothing there to trust.
  if (!(strongest > 0.0)) return near;
  const Eigen::Vector2d d(far.x() - near.x(), far.y() - near.y());
  Eigen::Vector2d kept = Eigen::Vector2d::Zero();
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d v = eigen.eigenvectors().col(k);
    if (eigen.eigenvalues()(k) >= ratio * strongest) kept += v.dot(d) * v;
  }
  return Pose2(near.x() + kept.x(), near.y() + kept.y(), far.theta());
}

void Rbpf::Resample(const std::vector<double>& weights) {
  const std::vector<int> keep = slam::Resample(weights, options_.resampling, rng_);
  std::vector<RbpfParticle> resampled;
  resampled.reserve(particles_.size());
  // A copy shares the map's tiles and the trajectory's nodes with its source.
  for (const int k : keep) resampled.push_back(particles_[static_cast<std::size_t>(k)]);
  for (RbpfParticle& p : resampled) p.log_weight = 0.0;
  particles_ = std::move(resampled);
  ++resample_count_;
}

RbpfStep Rbpf::AddScan(const LaserScan& scan, const Pose2& odometry_increment,
                       double odometry_gap_s) {
  RbpfStep step;
  if (!started_) {
    // Every particle starts at the identity with the first scan's map, all tiles shared.
    started_ = true;
    RbpfParticle first{Pose2(), 0.0, 0.0, TiledGrid(options_.map),
                       std::make_shared<RbpfPoseNode>(Pose2(), nullptr)};
    first.map.RecordHitMeans(options_.cell_hit_means);
    first.map.InsertScan(scan, Pose2(), SparseScanRange(scan, options_.points));
    particles_.assign(static_cast<std::size_t>(options_.num_particles), first);
    update_count_ = 1;
    step.neff = options_.num_particles;
    step.updated = true;
    last_step_ = step;
    return step;
  }
  pending_motion_ = pending_motion_ * odometry_increment;
  pending_gap_s_ = std::max(pending_gap_s_, odometry_gap_s);
  // After a gap the odometry's silence is no evidence of standing still: update at once.
  const bool after_gap = options_.odometry_gap_s > 0.0 && pending_gap_s_ > options_.odometry_gap_s;
  if (!after_gap && pending_motion_.translation().norm() < options_.min_update_distance_m &&
      std::abs(pending_motion_.theta()) < options_.min_update_angle_rad) {
    step = last_step_;
    step.best_pose = last_step_.best_pose * pending_motion_;
    step.mean_pose = last_step_.mean_pose * pending_motion_;
    step.resampled = false;
    step.updated = false;
    step.failed_matches = 0;
    return step;
  }
  const Pose2 pending = pending_motion_;
  update_odometry_.push_back(pending);
  pending_motion_ = Pose2();
  pending_gap_s_ = 0.0;
  step.updated = true;
  ++update_count_;

  // One seed per particle, drawn in order: the noise does not depend on the thread count.
  const int n = options_.num_particles;
  std::vector<std::uint64_t> seeds(static_cast<std::size_t>(n));
  for (std::uint64_t& s : seeds) s = rng_();
  std::vector<MatchPoint> points =
      MakeMatchPoints(scan, options_.points, options_.map.resolution_m);
  if (options_.weight_correlation_per_point) {
    AssignIndependenceWeights(points, options_.weight_correlation_length_m);
  }
  std::optional<ClimbResult> near_climb;
  const Pose2 motion =
      ChooseMotion(pending, after_gap, points, &step.odometry_rejected, &near_climb);
  // Before the particles write the scan into their maps: the map as it was, where the scan
  // fits it poorly.
  const std::optional<MapCheck> map_check = StartMapCheck(motion, points, near_climb);
  const double weight_exponent = WeightExponent(points);
  step.weight_exponent = weight_exponent;
  if (options_.weight_correlation_per_point && !points.empty()) {
    // The mean per-point factor: the scan's exponent had it tempered as a whole.
    double total = 0.0;
    for (const MatchPoint& p : points) total += p.weight;
    step.weight_exponent *= total / static_cast<double>(points.size());
  }
  std::vector<char> failed(static_cast<std::size_t>(n), 0);
  const ScanUpdate update{motion, &points, &scan, SparseScanRange(scan, options_.points),
                          weight_exponent};
  auto update_block = [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      bool f = false;
      UpdateParticle(particles_[k], update, seeds[k], &f);
      failed[k] = f;
    }
  };
  if (pool_) {
    pool_->ParallelFor(n, update_block);
  } else {
    update_block(0, n);
  }
  step.failed_matches = static_cast<int>(std::count(failed.begin(), failed.end(), 1));

  std::vector<double> log_weights(particles_.size());
  for (std::size_t i = 0; i < particles_.size(); ++i) log_weights[i] = particles_[i].log_weight;
  const std::vector<double> weights = SoftmaxWeights(log_weights);
  std::vector<Particle> cloud(particles_.size());
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    // Normalised logs keep the weights bounded; the ratios are unchanged.
    particles_[i].log_weight =
        weights[i] > 0.0 ? std::log(weights[i]) : -std::numeric_limits<double>::infinity();
    cloud[i] = Particle{particles_[i].pose, weights[i]};
  }
  step.mean_pose = WeightedMeanPose(cloud);
  step.neff = EffectiveSampleSize(weights);
  if (step.neff < options_.resample_neff_ratio * n) {
    Resample(weights);
    step.resampled = true;
  }
  best_ = 0;
  for (std::size_t i = 1; i < particles_.size(); ++i) {
    if (particles_[i].path_log_likelihood > particles_[best_].path_log_likelihood) best_ = i;
  }
  step.best_pose = particles_[best_].pose;
  const std::optional<Pose2> witness =
      map_check ? FinishMapCheck(*map_check, points, step.best_pose) : std::nullopt;
  if (witness) {
    step.map_contradiction_m = RingOffsetRms(step.best_pose, *witness, kContradictionRadiusM);
    map_witnesses_.push_back({update_count_ - 1, *witness});
  }
  step.matched_fraction = MatchedFraction(particles_[best_].map, points, step.best_pose);
  if (!points.empty() && !(step.matched_fraction < kPoorMatchShare * matched_level_)) {
    constexpr double kLevelRate = 0.02;
    matched_level_ = matched_samples_ == 0
                         ? step.matched_fraction
                         : matched_level_ + kLevelRate * (step.matched_fraction - matched_level_);
    ++matched_samples_;
  }
  last_step_ = step;
  return step;
}

std::vector<Pose2> Rbpf::BestUpdatePoses() const {
  std::vector<Pose2> poses;
  if (particles_.empty()) return poses;
  poses.reserve(static_cast<std::size_t>(update_count_));
  for (const RbpfPoseNode* node = best().history.get(); node; node = node->parent.get()) {
    poses.push_back(node->pose);
  }
  std::reverse(poses.begin(), poses.end());
  return poses;
}

double Rbpf::MapContradictionM() const {
  if (map_witnesses_.empty()) return 0.0;
  const std::vector<Pose2> path = BestUpdatePoses();
  SLAMRIG_CHECK(update_odometry_.size() + 1 == path.size(),
                "rbpf: one odometry increment per update after the first");
  double worst = 0.0;
  for (const RbpfMapWitness& w : map_witnesses_) {
    SLAMRIG_CHECK(w.update >= 1 && static_cast<std::size_t>(w.update) < path.size(),
                  "rbpf: a map witness names an update the best path does not hold");
    // The witness carried on by the odometry: a path that came back to the map's place within
    // kContradictionRadiusM of travel took the contradiction back.
    Pose2 carried = w.place;
    double travel_m = 0.0;
    double least = std::numeric_limits<double>::infinity();
    for (auto j = static_cast<std::size_t>(w.update); j < path.size(); ++j) {
      if (j > static_cast<std::size_t>(w.update)) {
        const Pose2& increment = update_odometry_[j - 1];
        carried = carried * increment;
        travel_m += increment.translation().norm();
      }
      least = std::min(least, RingOffsetRms(path[j], carried, kContradictionRadiusM));
      if (travel_m >= kContradictionRadiusM) break;
    }
    worst = std::max(worst, least);
  }
  return worst;
}

int Rbpf::DistinctTiles() const {
  std::vector<const TiledGrid::Tile*> tiles;
  for (const RbpfParticle& p : particles_) p.map.CollectTiles(&tiles);
  std::sort(tiles.begin(), tiles.end());
  return static_cast<int>(std::unique(tiles.begin(), tiles.end()) - tiles.begin());
}

}  // namespace slamrig::slam
