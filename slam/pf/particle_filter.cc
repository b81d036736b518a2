// Particle-filter SLAM after the UCSD ECE276A reports:
//  - prediction with the differential-drive odometry increment plus Gaussian noise (Wang, Eq. 6)
//    or the rot-trans-rot alpha model (Probabilistic Robotics, Table 5.6);
//  - update with the laser correlation model over a 9x9 (+yaw) shift grid and softmax weights,
//    alpha_k <- alpha_k exp(corr_k) / sum (Wang, Eq. 7; Zafari, step 5), or the likelihood field;
//  - map update from the best particle with log-odds +log 4 / free decrement / clamps (Wang, Eq.
//  17);
//  - resampling when Neff = 1 / sum alpha^2 < 0.5 N (Zafari, Eq. 6), stratified or systematic;
//  - degeneracy: solution remapping along the directions the scan's geometry leaves open (Zhang,
//    Kaess, Singh, ICRA 2016, Eq. 11);
//  - lost-filter detection from short- and long-term averages of the match quality (augmented
//    MCL, Probabilistic Robotics, Table 8.3) and relocalisation by a global branch-and-bound
//    match on the map built so far (Hess et al., ICRA 2016, Sec. V).
#include "slam/pf/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/matching/scan_points.h"
#include "slam/matching/solution_remapping.h"
#include "slam/odometry/gaussian.h"
#include "slam/types/check.h"

namespace slamrig::slam {
namespace {
// Surface normals from the scan points within this distance along the scan.
constexpr double kNeighbourM = 0.3;
// A scan is judged (the lost test, the tracked hypothesis while lost) only when at least this
// fraction of its points lands on observed map cells: unexplored space scores nothing anywhere.
constexpr double kJudgedFraction = 0.5;
// The global search needs this many points within search_max_range_m to place a scan.
constexpr std::size_t kMinGlobalSearchPoints = 10;
// The global search's yaw window: every heading.
constexpr double kEveryHeadingRad = 3.14159265358979;

// The farthest point of a scan from the robot.
double Reach(const std::vector<Eigen::Vector2d>& points) {
  double reach = 0.0;
  for (const Eigen::Vector2d& q : points) reach = std::max(reach, q.norm());
  return reach;
}
}  // namespace

Pose2 WeightedMeanPose(const std::vector<Particle>& particles) {
  double x = 0.0, y = 0.0, c = 0.0, s = 0.0, total = 0.0;
  for (const Particle& p : particles) {
    x += p.weight * p.pose.x();
    y += p.weight * p.pose.y();
    c += p.weight * std::cos(p.pose.theta());
    s += p.weight * std::sin(p.pose.theta());
    total += p.weight;
  }
  if (!(total > 0.0)) return particles.empty() ? Pose2() : particles.front().pose;
  return Pose2(x / total, y / total, std::atan2(s, c));
}

ParticleFilter::ParticleFilter(const ParticleFilterOptions& options)
    : options_(options),
      map_(options.map),
      correlator_(options.correlation),
      likelihood_field_(options.likelihood_field),
      field_sigma_(options.adaptive_sigma),
      occupied_mask_(options.correlation.occupied_threshold),
      refiner_(options.refiner),
      rng_(options.seed),
      calibration_(options.odometry_calibration) {
  SLAMRIG_CHECK_VALID(options_, "ParticleFilterOptions");
  if (const int threads = ThreadCount(options_.num_threads); threads > 1) {
    pool_ = std::make_unique<ThreadPool>(threads);
  }
  const int n = options_.num_particles;
  particles_.assign(static_cast<std::size_t>(n), Particle{Pose2(), 1.0 / n});
  log_weights_.assign(static_cast<std::size_t>(n), 0.0);
}

void ParticleFilter::Predict(const Pose2& odometry_increment) {
  // Sequential draws from one stream: the noise never depends on the thread count.
  for (Particle& p : particles_) {
    if (options_.motion_noise == MotionNoiseModel::kRotTransRot) {
      p.pose = p.pose * SampleRotTransRot(odometry_increment, options_.rot_trans_rot, rng_);
    } else {
      const Pose2 moved = p.pose * odometry_increment;
      const double nx = options_.sigma_xy_m * StandardNormal(rng_);
      const double ny = options_.sigma_xy_m * StandardNormal(rng_);
      const double nt = options_.sigma_yaw_rad * StandardNormal(rng_);
      p.pose = Pose2(moved.x() + nx, moved.y() + ny, moved.theta() + nt);
    }
  }
}

Eigen::AlignedBox2d ParticleFilter::ScanRegion(const Eigen::AlignedBox2d& poses,
                                               const std::vector<Eigen::Vector2d>& points) const {
  const double margin = Reach(points) +
                        (options_.correlation.xy_half_width_cells + 2) * map_.resolution() +
                        options_.likelihood_field.cutoff_sigmas * likelihood_field_.sigma_m();
  const Eigen::Vector2d m = Eigen::Vector2d::Constant(margin);
  return Eigen::AlignedBox2d(poses.min() - m, poses.max() + m);
}

Eigen::AlignedBox2d ParticleFilter::ScanRegion(const Eigen::Vector2d& position,
                                               const std::vector<Eigen::Vector2d>& points) const {
  return ScanRegion(Eigen::AlignedBox2d(position, position), points);
}

GridView ParticleFilter::MapWindow(const Eigen::AlignedBox2d& region) {
  const auto [lo, hi] = map_.CellsIn(region);
  const Eigen::Array2i size = (hi - lo + 1).max(Eigen::Array2i(0, 0));
  map_window_.resize(static_cast<std::size_t>(size.x()) * static_cast<std::size_t>(size.y()));
  map_.CopyLogOdds(lo, size, map_window_.data(), size.x());
  return GridView{map_window_.data(), size.x(), size.y(),
                  map_.origin() + lo.cast<double>().matrix() * map_.resolution(),
                  map_.resolution()};
}

std::vector<double> ParticleFilter::Score(const std::vector<Eigen::Vector2d>& points,
                                          const MatchConstraints& constraints,
                                          const Pose2& predicted_mean, float* best_score) {
  const int n = options_.num_particles;
  const bool use_field = options_.observation == ObservationModel::kLikelihoodField;
  // The field (or the map's window) only needs to cover where this scan can land for some
  // particle and shift.
  Eigen::AlignedBox2d particles_box;
  for (const Particle& p : particles_) particles_box.extend(p.pose.translation());
  const Eigen::AlignedBox2d region = ScanRegion(particles_box, points);
  GridView field_view;
  if (use_field || options_.refine) {
    // Kept up to date where the map changed; the window keeps reads outside it at 0.
    likelihood_field_.Follow(map_, region);
    field_view = likelihood_field_.view(region);
  }
  // The occupied indicator on the map itself reads a bit raster kept up to date where the map
  // changed (only when the field does not follow the map: one follower per grid); other values
  // on the map read a copy of its window.
  const OccupiedMask* walls = nullptr;
  GridView view = field_view;
  if (!use_field) {
    if (!options_.refine && options_.correlation.value == CorrelationValue::kOccupiedIndicator) {
      occupied_mask_.Follow(map_);
      walls = &occupied_mask_;
      view = GridView::LatticeOf(map_);
    } else {
      view = MapWindow(region);
    }
  }
  const float field_max = static_cast<float>(likelihood_field_.Score(0.0));
  std::vector<CorrelationResult> results(static_cast<std::size_t>(n));
  const double ratio = options_.degeneracy_ratio;
  const bool weak = ratio > 0.0 && constraints.WeakCount(ratio) > 0;
  auto score_block = [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      CorrelationResult& r = results[static_cast<std::size_t>(i)];
      const Pose2& predicted = particles_[static_cast<std::size_t>(i)].pose;
      r = walls ? correlator_.Correlate(view, *walls, points, predicted)
                : correlator_.Correlate(view, points, predicted);
      if (options_.refine) {
        // The refiner's prior stays on the predicted pose, not on the shift the search chose.
        const RefineResult refined =
            refiner_.Refine(field_view, field_max, points, r.pose, predicted);
        r.pose = refined.pose;
        if (use_field) r.score = static_cast<float>(refined.score);
      }
      // Degeneracy: along the directions the scan does not constrain the particle keeps its
      // prediction, and its weight is the score with those coordinates replaced by the cloud's
      // mean, so that it cannot depend on them: a map built from behind scores poses that lag
      // higher, and resampling on that would drag the cloud back along a corridor.
      if (weak) {
        r.pose = RemapAlongWeakDirections(predicted, r.pose, constraints, ratio);
        if (use_field) {
          const Pose2 weighed =
              RemapAlongWeakDirections(predicted_mean, r.pose, constraints, ratio);
          r.score = static_cast<float>(ScanRefiner::Score(field_view, points, weighed));
        }
      }
    }
  };
  if (pool_) {
    pool_->ParallelFor(n, score_block);
  } else {
    score_block(0, n);
  }
  std::vector<double> scores(static_cast<std::size_t>(n));
  *best_score = -std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < results.size(); ++i) {
    scores[i] = results[i].score;
    *best_score = std::max(*best_score, results[i].score);
    if (options_.move_to_best_shift) particles_[i].pose = results[i].pose;
  }
  return scores;
}

void ParticleFilter::HoldMeanAlongWeakDirections(const Pose2& predicted_mean,
                                                 const MatchConstraints& constraints) {
  // Resampling draws the cloud's members by their cross-axis offset and heading; along the axis
  // their places are a random pick of the spread, and the weights can favour the places the map
  // was written from (behind). Either would move the cloud's mean along the axis, update after
  // update; the whole cloud is shifted back so that its mean follows the odometry there.
  const Pose2 now = WeightedMeanPose(particles_);
  const Pose2 held =
      RemapAlongWeakDirections(predicted_mean, now, constraints, options_.degeneracy_ratio);
  const Eigen::Vector2d shift = held.translation() - now.translation();
  for (Particle& p : particles_) {
    p.pose = Pose2(p.pose.x() + shift.x(), p.pose.y() + shift.y(), p.pose.theta());
  }
}

bool ParticleFilter::Unimodal(const Pose2& mean) const {
  const double r = options_.unimodal_radius_m, a = options_.unimodal_yaw_rad;
  if (!(r > 0.0) || !(a > 0.0)) return false;
  // Particles of negligible weight do not move the mean; they do not count.
  const double negligible = 0.1 / options_.num_particles;
  for (const Particle& p : particles_) {
    if (p.weight < negligible) continue;
    if ((p.pose.translation() - mean.translation()).norm() > r ||
        std::abs(NormalizeAngle(p.pose.theta() - mean.theta())) > a) {
      return false;
    }
  }
  return true;
}

double ParticleFilter::Quality(float score, std::size_t num_points) const {
  const double field_max = likelihood_field_.Score(0.0);
  if (num_points == 0 || !(field_max > 0.0)) return 0.0;
  return std::clamp(static_cast<double>(score) / (field_max * static_cast<double>(num_points)), 0.0,
                    1.0);
}

bool ParticleFilter::TrackQuality(double quality, Time now) {
  const RelocalisationOptions& o = options_.relocalisation;
  if (!o.enabled || options_.observation != ObservationModel::kLikelihoodField) return false;
  ++tracked_updates_;
  if (tracked_updates_ == 1) {
    quality_fast_ = quality_slow_ = quality;
    return false;
  }
  const bool warm = tracked_updates_ > o.warmup_updates;
  const bool suspect = warm && quality < o.lost_ratio * quality_slow_;
  quality_fast_ += o.fast_rate * (quality - quality_fast_);
  // The long-term average is the level to come back to: suspect scans do not drag it down.
  if (!suspect) quality_slow_ += o.slow_rate * (quality - quality_slow_);
  if (warm && quality_fast_ < o.lost_ratio * quality_slow_) {
    lost_ = true;
    lost_since_ = now;
    lost_pose_ = last_step_.best_pose;
    ++lost_count_;
    ForgetSearch();
    unsupported_updates_ = 0;
  }
  return suspect;
}

bool ParticleFilter::Relocalise(const std::vector<Eigen::Vector2d>& points, const LaserScan& scan,
                                ParticleFilterStep* step) {
  step->lost = true;
  LostVerdict verdict{LostDecision::kStayLost, Pose2()};
  if (!points.empty()) {
    // Two hypotheses, judged alike and tracked in parallel: the filter's own (its cloud goes on
    // being predicted, scan-matched and resampled while lost, only the map is frozen), and a
    // place elsewhere on the map.
    const ScoredPose tracked{step->best_pose, step->quality};
    if (ObservedFraction(points, tracked.pose) < kJudgedFraction) {
      // The tracked hypothesis's scan reaches mostly into ground the map has not seen: nothing
      // can refute it there (the lost test itself is made only on mapped ground), and on a
      // frozen map the filter would go on scoring against nothing. Tracking resumes and the new
      // ground is mapped.
      verdict = {LostDecision::kResume, Pose2()};
    } else {
      std::vector<Candidate> places = FollowCandidates(points);
      GatherGlobalPlaces(points, &places);
      verdict = Decide(points, tracked, std::move(places));
    }
  }
  switch (verdict.decision) {
    case LostDecision::kResume:
      ResumeTracking();
      step->lost = false;
      return false;
    case LostDecision::kCorrectSlip: {
      // The best place near by fits better than the filter's: the odometry slipped, no
      // kidnapping. Tracking resumes there.
      MoveCloud(verdict.pose, step);
      ResumeTracking();
      step->lost = false;
      return false;
    }
    case LostDecision::kStayLost:
      GiveUpWhenLostTooLong(scan, step);
      return true;
    case LostDecision::kRelocalise:
      RestartAt(verdict.pose, step);
      return true;
  }
  return true;
}

std::vector<ParticleFilter::Candidate> ParticleFilter::FollowCandidates(
    const std::vector<Eigen::Vector2d>& points) {
  // The places of the previous updates, carried by the odometry (AddScan), must explain this scan
  // where the odometry put them: matched locally, each stays within confirm_distance_m and
  // confirm_angle_rad of that prediction and fits as well as a place must. A wrong place that
  // happens to fit one scan (an aliased corridor) rarely fits the next ones at the same relative
  // pose. Two that converge on one place are one.
  const RelocalisationOptions& o = options_.relocalisation;
  std::vector<Candidate> places;
  for (const Candidate& c : candidates_) {
    const ScoredPose followed = LocalMatch(points, c.pose);
    const bool stayed =
        (followed.pose.translation() - c.pose.translation()).norm() <= o.confirm_distance_m &&
        std::abs(NormalizeAngle(followed.pose.theta() - c.pose.theta())) <= o.confirm_angle_rad;
    if (!stayed || !FitsAsPlace(followed.quality)) continue;
    bool merged = false;
    for (Candidate& p : places) {
      if (DistinctPlaces(p.pose, followed.pose)) continue;
      merged = true;
      if (followed.quality > p.quality) p = Candidate{followed.pose, followed.quality, c.wins};
    }
    if (!merged) places.push_back(Candidate{followed.pose, followed.quality, c.wins});
  }
  return places;
}

void ParticleFilter::GatherGlobalPlaces(const std::vector<Eigen::Vector2d>& points,
                                        std::vector<Candidate>* places) {
  // The whole map is searched on every lost update for its best distinct places, so that a place
  // is judged against the best other explanation of this scan, not only against the ones it
  // was found with.
  std::vector<Eigen::Vector2d> near;
  for (const Eigen::Vector2d& p : points) {
    if (p.norm() <= options_.relocalisation.search_max_range_m) near.push_back(p);
  }
  if (near.size() < kMinGlobalSearchPoints) return;
  for (const ScoredPose& g : GlobalMatches(near, points)) {
    bool known = false;
    for (const Candidate& p : *places) known = known || !DistinctPlaces(p.pose, g.pose);
    if (!known) places->push_back(Candidate{g.pose, g.quality, 0});
  }
}

ParticleFilter::LostVerdict ParticleFilter::Decide(const std::vector<Eigen::Vector2d>& points,
                                                   const ScoredPose& tracked,
                                                   std::vector<Candidate> places) {
  const RelocalisationOptions& o = options_.relocalisation;
  // The leading place, and the best of the others.
  const Candidate* found = nullptr;
  double rival_quality = 0.0;
  for (const Candidate& p : places) {
    if (!found || p.quality > found->quality) {
      if (found) rival_quality = std::max(rival_quality, found->quality);
      found = &p;
    } else {
      rival_quality = std::max(rival_quality, p.quality);
    }
  }
  // The tracked hypothesis is the best explanation near the filter, not only at its pose: the
  // odometry may have slipped by more than the shift search covers (a wheel on a threshold, a
  // fast turn), and a kidnapping is far rarer than a slip. A place elsewhere must fit the scan
  // clearly better than anything near by; a bad scan (people, glass, clutter) fits nowhere better
  // than where the robot is.
  const std::optional<ScoredPose> nearby = NearMatch(points, tracked.pose);
  const double near_quality = nearby ? std::max(nearby->quality, tracked.quality) : tracked.quality;
  const double slip = found ? (found->pose.translation() - tracked.pose.translation()).norm() : 0.0;
  const bool elsewhere = found && slip > o.slip_radius_m &&
                         found->quality >= near_quality + o.win_margin * quality_slow_;
  if (!elsewhere && nearby && nearby->quality > tracked.quality) {
    return {LostDecision::kCorrectSlip, nearby->pose};
  }
  if (!elsewhere) {
    ClearCandidates();
    ++unsupported_updates_;
    // The test is sequential both ways: a place elsewhere must win on confirm_updates updates in
    // a row, and resume_updates updates in a row on which nothing elsewhere fits better keep the
    // filter where it is, even when it fits poorly there (a young or changed part of the map).
    // So does a tracked hypothesis that fits as well as usual again: the alarm was a bad scan.
    if (FitsAsPlace(tracked.quality) || unsupported_updates_ >= o.resume_updates) {
      return {LostDecision::kResume, Pose2()};
    }
    return {LostDecision::kStayLost, Pose2()};
  }
  unsupported_updates_ = 0;
  // A place elsewhere wins, but it wins outright only when no other distinct place fits nearly
  // as well: aliased bays keep the filter lost, every place still followed, until the scans
  // tell them apart.
  const bool clear = found->quality >= rival_quality + o.ambiguity_margin * quality_slow_;
  const Candidate winner = *found;
  for (Candidate& p : places) p.wins = 0;
  candidates_ = std::move(places);
  if (!clear) return {LostDecision::kStayLost, Pose2()};
  const int wins = winner.wins + 1;
  for (Candidate& p : candidates_) {
    if (p.pose == winner.pose) p.wins = wins;
  }
  if (wins < o.confirm_updates) return {LostDecision::kStayLost, Pose2()};
  return {LostDecision::kRelocalise, winner.pose};
}

void ParticleFilter::RestartAt(const Pose2& place, ParticleFilterStep* step) {
  const RelocalisationOptions& o = options_.relocalisation;
  const double uniform = 1.0 / options_.num_particles;
  for (Particle& p : particles_) {
    const Eigen::Vector3d n = StandardNormal3(rng_);
    p.pose = Pose2(place.x() + o.reset_sigma_xy_m * n.x(), place.y() + o.reset_sigma_xy_m * n.y(),
                   place.theta() + o.reset_sigma_yaw_rad * n.z());
    p.weight = uniform;
  }
  std::fill(log_weights_.begin(), log_weights_.end(), 0.0);
  lost_ = false;
  ForgetSearch();
  quality_fast_ = quality_slow_;
  ++relocalisation_count_;
  step->lost = false;
  step->relocalised = true;
  step->best_pose = place;
  step->mean_pose = place;
  step->neff = static_cast<double>(options_.num_particles);
}

bool ParticleFilter::DistinctPlaces(const Pose2& a, const Pose2& b) const {
  const RelocalisationOptions& o = options_.relocalisation;
  return (a.translation() - b.translation()).norm() > o.distinct_radius_m ||
         std::abs(NormalizeAngle(a.theta() - b.theta())) > o.distinct_angle_rad;
}

double ParticleFilter::ObservedFraction(const std::vector<Eigen::Vector2d>& points,
                                        const Pose2& pose) const {
  if (points.empty()) return 0.0;
  std::size_t known = 0;
  for (const Eigen::Vector2d& q : points) {
    // A hit just behind a wall lands in a never-observed cell next to the wall's: observed
    // means the cell or one of its eight neighbours.
    const Eigen::Array2i c = map_.WorldToCell(pose * q);
    bool observed = false;
    for (int dy = -1; dy <= 1 && !observed; ++dy) {
      for (int dx = -1; dx <= 1 && !observed; ++dx) {
        observed = map_.LogOdds(c + Eigen::Array2i(dx, dy)) != 0.0f;
      }
    }
    known += observed;
  }
  return static_cast<double>(known) / static_cast<double>(points.size());
}

void ParticleFilter::ClearCandidates() { candidates_.clear(); }

void ParticleFilter::ForgetSearch() {
  ClearCandidates();
  global_matcher_.reset();
  near_matcher_.reset();
}

void ParticleFilter::ResumeTracking() {
  lost_ = false;
  ForgetSearch();
  quality_fast_ = quality_slow_;
  ++resumed_count_;
}

void ParticleFilter::GiveUpWhenLostTooLong(const LaserScan& scan, ParticleFilterStep* step) {
  if (SecondsBetween(scan.time, lost_since_) <= options_.relocalisation.max_lost_s) return;
  // Nowhere on the map fits: the robot is somewhere new, map on from the odometry.
  lost_ = false;
  ForgetSearch();
  tracked_updates_ = 0;
  step->lost = false;
  map_.InsertScan(scan, step->best_pose, SparseScanRange(scan, options_.points));
}

ParticleFilter::ScoredPose ParticleFilter::LocalMatch(const std::vector<Eigen::Vector2d>& points,
                                                      const Pose2& pose) {
  const Eigen::AlignedBox2d region = ScanRegion(pose.translation(), points);
  likelihood_field_.Follow(map_, region);
  const GridView view = likelihood_field_.view(region);
  const float field_max = static_cast<float>(likelihood_field_.Score(0.0));
  const CorrelationResult shifted = correlator_.Correlate(view, points, pose);
  const RefineResult refined = refiner_.Refine(view, field_max, points, shifted.pose);
  return {refined.pose, Quality(static_cast<float>(refined.score), points.size())};
}

std::vector<ParticleFilter::ScoredPose> ParticleFilter::GlobalMatches(
    const std::vector<Eigen::Vector2d>& near, const std::vector<Eigen::Vector2d>& points) {
  const RelocalisationOptions& o = options_.relocalisation;
  if (!global_matcher_) {
    // The map is frozen while lost: one set of precomputation grids serves every search. The
    // window is the map's extent, up to search_window_m around where the filter was lost.
    const Eigen::Vector2d extent = Eigen::Vector2d(map_.width(), map_.height()) * map_.resolution();
    const Eigen::Vector2d lo = map_.origin(), hi = map_.origin() + extent;
    const Eigen::Vector2d w = Eigen::Vector2d::Constant(o.search_window_m);
    const Eigen::Vector2d from = lost_pose_.translation() - w, to = lost_pose_.translation() + w;
    const Eigen::Vector2d a = from.cwiseMax(lo), b = to.cwiseMin(hi);
    search_centre_ = 0.5 * (a + b);
    CorrelativeMatcherOptions m;
    m.linear_window_m = 0.5 * (b - a).cwiseMax(0.0).maxCoeff();
    m.angular_window_rad = kEveryHeadingRad;
    m.min_score = 0.0;
    const int decimation =
        std::max(1, static_cast<int>(std::lround(o.search_resolution_m / map_.resolution())));
    // Only the map within reach of the window counts: the precomputation costs that, not the
    // map (the global search's points reach search_max_range_m).
    const Eigen::Vector2d reach =
        Eigen::Vector2d::Constant(o.search_max_range_m + (decimation + 1) * map_.resolution());
    global_matcher_ = std::make_unique<CorrelativeMatcher>(
        m, map_, decimation, Eigen::AlignedBox2d(a - reach, b + reach));
  }
  std::vector<ScoredPose> places;
  for (const MatchResult& match : global_matcher_->MatchDistinct(
           near, Pose2(search_centre_.x(), search_centre_.y(), 0.0), o.global_candidates,
           o.distinct_radius_m, o.distinct_angle_rad)) {
    // The coarse raster places the scan to within a coarse cell and yaw step: the shift search
    // and refinement at the map's resolution take it from there.
    const ScoredPose place = LocalMatch(points, match.pose);
    if (FitsAsPlace(place.quality)) places.push_back(place);
  }
  return places;
}

std::optional<ParticleFilter::ScoredPose> ParticleFilter::NearMatch(
    const std::vector<Eigen::Vector2d>& points, const Pose2& pose) {
  const RelocalisationOptions& o = options_.relocalisation;
  // The map is frozen while lost: one set of precomputation grids serves every search from near
  // where it was built, over the map within reach of the search (never the whole map).
  const double needed = o.slip_radius_m + Reach(points) + 2.0 * map_.resolution();
  if (!near_matcher_ ||
      (pose.translation() - near_centre_).cwiseAbs().maxCoeff() + needed > near_half_side_m_) {
    constexpr double kSlackM = 5.0;  // the robot may move this far, lost, before a rebuild
    near_centre_ = pose.translation();
    near_half_side_m_ = needed + kSlackM;
    const Eigen::Vector2d half = Eigen::Vector2d::Constant(near_half_side_m_);
    CorrelativeMatcherOptions m;
    m.linear_window_m = o.slip_radius_m;
    m.angular_window_rad = o.slip_angle_rad;
    m.min_score = 0.0;
    near_matcher_ = std::make_unique<CorrelativeMatcher>(
        m, map_, 1, Eigen::AlignedBox2d(near_centre_ - half, near_centre_ + half));
  }
  const std::optional<MatchResult> match = near_matcher_->Match(points, pose);
  if (!match) return std::nullopt;
  return AcceptedPlace(points, match->pose);
}

std::optional<ParticleFilter::ScoredPose> ParticleFilter::AcceptedPlace(
    const std::vector<Eigen::Vector2d>& points, const Pose2& pose) {
  // Judged as the tracking judges itself: refined on the likelihood field, all points.
  const Eigen::AlignedBox2d region = ScanRegion(pose.translation(), points);
  likelihood_field_.Follow(map_, region);
  const float field_max = static_cast<float>(likelihood_field_.Score(0.0));
  const RefineResult refined =
      refiner_.Refine(likelihood_field_.view(region), field_max, points, pose);
  const double quality = Quality(static_cast<float>(refined.score), points.size());
  if (!FitsAsPlace(quality)) return std::nullopt;
  return ScoredPose{refined.pose, quality};
}

void ParticleFilter::MoveCloud(const Pose2& to, ParticleFilterStep* step) {
  const Pose2 correction = to * step->best_pose.Inverse();
  for (Particle& p : particles_) p.pose = correction * p.pose;
  step->best_pose = correction * step->best_pose;
  step->mean_pose = correction * step->mean_pose;
}

bool ParticleFilter::SearchNear(const std::vector<Eigen::Vector2d>& points, double radius_m,
                                ParticleFilterStep* step) {
  const RelocalisationOptions& o = options_.relocalisation;
  // The places' bar is the long-term quality: none before it is trusted.
  if (!o.enabled || options_.observation != ObservationModel::kLikelihoodField ||
      tracked_updates_ <= o.warmup_updates || points.size() < kMinGlobalSearchPoints) {
    return false;
  }
  // A one-off search (the map changes with every update): the map within reach of the window.
  const Pose2& here = step->best_pose;
  const double half = radius_m + Reach(points) + 2.0 * map_.resolution();
  const Eigen::Vector2d h = Eigen::Vector2d::Constant(half);
  CorrelativeMatcherOptions m;
  m.linear_window_m = radius_m;
  m.angular_window_rad = kEveryHeadingRad;
  m.min_score = 0.0;
  const CorrelativeMatcher matcher(
      m, map_, 1, Eigen::AlignedBox2d(here.translation() - h, here.translation() + h));
  const std::optional<MatchResult> match = matcher.Match(points, here);
  if (!match) return false;
  const std::optional<ScoredPose> place = AcceptedPlace(points, match->pose);
  if (!place || !(place->quality > step->quality + o.win_margin * quality_slow_)) return false;
  MoveCloud(place->pose, step);
  step->quality = place->quality;
  ++gap_correction_count_;
  return true;
}

bool ParticleFilter::FitsAsPlace(double quality) const {
  return quality >= options_.relocalisation.accept_ratio * quality_slow_;
}

ParticleFilterStep ParticleFilter::AddScan(const LaserScan& scan, const Pose2& odometry_increment,
                                           double odometry_gap_s) {
  if (!started_) return Start(scan);
  pending_motion_ = pending_motion_ * odometry_increment;
  pending_gap_s_ = std::max(pending_gap_s_, odometry_gap_s);
  const RelocalisationOptions& reloc = options_.relocalisation;
  const bool after_gap = reloc.odometry_gap_s > 0.0 && pending_gap_s_ > reloc.odometry_gap_s;
  // After a gap the odometry's silence is no evidence of standing still: update at once.
  if (!after_gap && !MovedEnough()) return FollowOdometry();
  pending_gap_s_ = 0.0;
  const Pose2 raw_motion = pending_motion_;
  const Pose2 motion = calibration_.Correct(raw_motion);
  Predict(motion);
  for (Candidate& c : candidates_) c.pose = c.pose * motion;
  pending_motion_ = Pose2();

  ParticleFilterStep step;
  step.updated = true;
  const std::vector<Eigen::Vector2d> all_points = ScanToBasePoints(scan, options_.points);
  const SelectedPoints selected = DropGrazingPoints(
      all_points, SurfaceNormals(all_points, kNeighbourM), options_.max_incidence_rad);
  const std::vector<Eigen::Vector2d>& points = selected.points;
  step.points_used = static_cast<int>(points.size());
  // The cloud's mean as the odometry moved it: along a degenerate direction it stays the estimate.
  const Pose2 predicted_mean = WeightedMeanPose(particles_);
  MatchConstraints constraints;
  if (!points.empty())
    constraints = DecomposeInformation(ScanInformation(points, selected.normals));
  const bool degenerate = !points.empty() && options_.degeneracy_ratio > 0.0 &&
                          constraints.WeakCount(options_.degeneracy_ratio) > 0;
  const std::vector<double> weights = UpdateWeights(points, constraints, predicted_mean, &step);
  ChooseEstimate(constraints, degenerate, predicted_mean, &step);
  step.quality = Quality(step.best_score, points.size());
  step.neff = EffectiveSampleSize(weights);
  if (!lost_) {
    if (after_gap) {
      step.gap_corrected = SearchNear(points, reloc.slip_radius_m, &step);
    } else if (scan_matched_increments_ && reloc.scan_matched_search_m > 0.0 &&
               !FitsAsPlace(step.quality)) {
      step.gap_corrected = SearchNear(points, reloc.scan_matched_search_m, &step);
    }
  }
  if (!UpdateMapAndLostState(scan, points, &step)) {
    last_step_ = step;
    return step;
  }
  if (step.neff < options_.resample_neff_ratio * options_.num_particles) {
    ResampleCloud(weights);
    step.resampled = true;
  }
  if (degenerate) HoldMeanAlongWeakDirections(predicted_mean, constraints);
  // The calibration learns from updates that tracked on both ends: a loss, a relocalisation or a
  // slip correction moves the estimate by more than the odometry's error.
  if (!points.empty() && !step.lost && !step.relocalised && !step.gap_corrected &&
      !last_step_.lost && !last_step_.relocalised) {
    calibration_.Observe(raw_motion, last_step_.best_pose.Inverse() * step.best_pose);
  }
  last_step_ = step;
  return step;
}

ParticleFilterStep ParticleFilter::Start(const LaserScan& scan) {
  // Step 1 of Zafari's summary: particles at the origin; the first scan starts the map.
  started_ = true;
  map_.InsertScan(scan, Pose2(), SparseScanRange(scan, options_.points));
  ParticleFilterStep step;
  step.neff = static_cast<double>(options_.num_particles);
  step.updated = true;
  last_step_ = step;
  return step;
}

bool ParticleFilter::MovedEnough() const {
  return pending_motion_.translation().norm() >= options_.min_update_distance_m ||
         std::abs(pending_motion_.theta()) >= options_.min_update_angle_rad;
}

ParticleFilterStep ParticleFilter::FollowOdometry() const {
  // Too little motion since the last update: no filtering, poses follow the odometry.
  ParticleFilterStep step = last_step_;
  const Pose2 motion = calibration_.Correct(pending_motion_);
  step.best_pose = last_step_.best_pose * motion;
  step.mean_pose = last_step_.mean_pose * motion;
  step.resampled = false;
  step.updated = false;
  return step;
}

std::vector<double> ParticleFilter::UpdateWeights(const std::vector<Eigen::Vector2d>& points,
                                                  const MatchConstraints& constraints,
                                                  const Pose2& predicted_mean,
                                                  ParticleFilterStep* step) {
  if (!points.empty()) {
    const std::vector<double> scores =
        Score(points, constraints, predicted_mean, &step->best_score);
    for (std::size_t i = 0; i < scores.size(); ++i) {
      log_weights_[i] += options_.observation_scale * scores[i];
    }
  }
  const std::vector<double> weights = SoftmaxWeights(log_weights_);
  std::size_t best = 0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].weight = weights[i];
    if (weights[i] > weights[best]) best = i;
    // Keep log-weights bounded: the normalised log is equivalent.
    log_weights_[i] =
        weights[i] > 0.0 ? std::log(weights[i]) : -std::numeric_limits<double>::infinity();
  }
  step->best_pose = particles_[best].pose;
  return weights;
}

void ParticleFilter::ChooseEstimate(const MatchConstraints& constraints, bool degenerate,
                                    const Pose2& predicted_mean, ParticleFilterStep* step) const {
  step->mean_pose = WeightedMeanPose(particles_);
  if (!degenerate && Unimodal(step->mean_pose)) {
    // One mode: its weighted mean is a better estimate than any one member (the scan-matched
    // particles scatter around the optimum by the refiner's convergence and the prediction's
    // noise), and the map built from it is smoother. Not along a degenerate direction: there the
    // particles keep their odometry, and the mean of that spread builds a worse corridor map.
    step->best_pose = step->mean_pose;
  }
  if (degenerate) {
    // Along the directions the scan leaves open the estimate is the cloud's mean where the
    // odometry put it, not any one particle's place there: the particles keep their own sampled
    // motion along the axis (the spread later scans can correct), and which of them carries the
    // most weight says nothing about it.
    step->best_pose = RemapAlongWeakDirections(predicted_mean, step->best_pose, constraints,
                                               options_.degeneracy_ratio);
    step->mean_pose = RemapAlongWeakDirections(predicted_mean, step->mean_pose, constraints,
                                               options_.degeneracy_ratio);
  }
}

bool ParticleFilter::UpdateMapAndLostState(const LaserScan& scan,
                                           const std::vector<Eigen::Vector2d>& points,
                                           ParticleFilterStep* step) {
  if (lost_) {
    // Lost since an earlier update: the map stays frozen until the filter resumes (the scan fits
    // where the filter is, or next to it, and is mapped as usual) or relocalises (a new cloud).
    if (!Relocalise(points, scan, step))
      map_.InsertScan(scan, step->best_pose, SparseScanRange(scan, options_.points));
    return !step->relocalised;
  }
  // The lost test is made only when most of the scan lands where the map has been observed:
  // points in unexplored space score nothing wherever the robot is, so a scan reaching mostly
  // into new ground (a first pass, an outdoor log's far returns) scores low without being lost.
  // (Scoring only the observed points instead would hide a kidnapping: a displaced scan's
  // points also leave the map.)
  const bool judged =
      !points.empty() && ObservedFraction(points, step->best_pose) >= kJudgedFraction;
  // How far this scan's points lie from the map's walls, read before the scan is inserted.
  std::optional<double> wall_distance;
  if (judged && options_.observation == ObservationModel::kLikelihoodField &&
      options_.adaptive_sigma.enabled) {
    likelihood_field_.Follow(map_, ScanRegion(step->best_pose.translation(), points));
    wall_distance = field_sigma_.MedianWallDistance(likelihood_field_, points, step->best_pose);
  }
  // A scan that matches the map much worse than usual is not inserted: after a kidnapping it
  // would paint the new place onto the old one before the averages call the filter lost.
  const bool suspect = judged && TrackQuality(step->quality, scan.time);
  step->lost = lost_;
  if (!suspect) map_.InsertScan(scan, step->best_pose, SparseScanRange(scan, options_.points));
  // A scan that tracked as usual tells how sharp the map is; the field follows (its next
  // Follow recomputes it everywhere).
  if (!suspect && !lost_ && wall_distance) {
    if (const std::optional<double> sigma =
            field_sigma_.Observe(*wall_distance, likelihood_field_.sigma_m())) {
      likelihood_field_.SetSigma(*sigma);
    }
  }
  // Just lost: the weights say nothing now; keep the cloud for the odometry to carry.
  return !lost_;
}

void ParticleFilter::ResampleCloud(const std::vector<double>& weights) {
  const std::vector<int> keep = Resample(weights, options_.resampling, rng_);
  std::vector<Particle> resampled;
  resampled.reserve(particles_.size());
  const double uniform = 1.0 / options_.num_particles;
  for (const int k : keep) {
    resampled.push_back(Particle{particles_[static_cast<std::size_t>(k)].pose, uniform});
  }
  particles_ = std::move(resampled);
  std::fill(log_weights_.begin(), log_weights_.end(), 0.0);
  ++resample_count_;
}

}  // namespace slamrig::slam
