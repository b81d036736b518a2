// Particle-filter SLAM after the UCSD ECE276A reports:
//  - prediction with the differential-drive odometry increment plus Gaussian noise (Wang, Eq. 6)
//    or the rot-trans-rot alpha model (Probabilistic Robotics, Table 5.6);
//  - update with the laser correlation model over a 9x9 (+yaw) shift grid and softmax weights,
//    alpha_k <- alpha_k exp(corr_k) / sum (Wang, Eq. 7; Zafari, step 5), or the likelihood field;
//  - map update from the best particle with log-odds +log 4 / free decrement / clamps (Wang, Eq.
//  17);
//  - resampling when Neff = 1 / sum alpha^2 < 0.5 N (Zafari, Eq. 6), stratified or systematic.
#include "slam/pf/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/matching/scan_points.h"
#include "slam/types/check.h"

namespace slamrig::slam {

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
      occupied_mask_(options.correlation.occupied_threshold),
      refiner_(options.refiner),
      rng_(options.seed) {
  SLAMRIG_CHECK(options_.Validate().empty(), "invalid ParticleFilterOptions");
  if (options_.num_threads > 1) pool_ = std::make_unique<ThreadPool>(options_.num_threads);
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

std::vector<double> ParticleFilter::Score(const std::vector<Eigen::Vector2d>& points,
                                          float* best_score) {
  const int n = options_.num_particles;
  const bool use_field = options_.observation == ObservationModel::kLikelihoodField;
  GridView field_view;
  if (use_field || options_.refine) {
    // The field only needs to cover where this scan can land for some particle and shift.
    Eigen::AlignedBox2d particles_box;
    for (const Particle& p : particles_) particles_box.extend(p.pose.translation());
    double reach = 0.0;
    for (const Eigen::Vector2d& q : points) reach = std::max(reach, q.norm());
    const double margin =
        reach + (options_.correlation.xy_half_width_cells + 2) * map_.resolution() +
        options_.likelihood_field.cutoff_sigmas * options_.likelihood_field.sigma_m;
    const Eigen::Vector2d m = Eigen::Vector2d::Constant(margin);
    // Kept up to date where the map changed; the window keeps reads outside it at 0.
    likelihood_field_.Follow(map_);
    field_view = likelihood_field_.view(
        Eigen::AlignedBox2d(particles_box.min() - m, particles_box.max() + m));
  }
  const GridView view = use_field ? field_view : GridView::Of(map_);
  // The occupied indicator on the map itself reads a bit raster kept up to date where the map
  // changed (only when the field does not follow the map: one follower per grid).
  const OccupiedMask* walls = nullptr;
  if (!use_field && !options_.refine &&
      options_.correlation.value == CorrelationValue::kOccupiedIndicator) {
    occupied_mask_.Follow(map_);
    walls = &occupied_mask_;
  }
  const float field_max = static_cast<float>(likelihood_field_.Score(0.0));
  std::vector<CorrelationResult> results(static_cast<std::size_t>(n));
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

ParticleFilterStep ParticleFilter::AddScan(const LaserScan& scan, const Pose2& odometry_increment) {
  ParticleFilterStep step;
  if (!started_) {
    // Step 1 of Zafari's summary: particles at the origin; the first scan starts the map.
    started_ = true;
    map_.InsertScan(scan, Pose2());
    step.neff = static_cast<double>(options_.num_particles);
    step.updated = true;
    last_step_ = step;
    return step;
  }
  // Too little motion since the last update: no filtering, poses follow the odometry.
  pending_motion_ = pending_motion_ * odometry_increment;
  const bool moved_enough =
      pending_motion_.translation().norm() >= options_.min_update_distance_m ||
      std::abs(pending_motion_.theta()) >= options_.min_update_angle_rad;
  if (!moved_enough) {
    step = last_step_;
    step.best_pose = last_step_.best_pose * pending_motion_;
    step.mean_pose = last_step_.mean_pose * pending_motion_;
    step.resampled = false;
    step.updated = false;
    return step;
  }
  Predict(pending_motion_);
  pending_motion_ = Pose2();
  step.updated = true;

  const std::vector<Eigen::Vector2d> points = ScanToBasePoints(scan, options_.points);
  step.points_used = static_cast<int>(points.size());
  if (!points.empty()) {
    const std::vector<double> scores = Score(points, &step.best_score);
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
  step.best_pose = particles_[best].pose;
  step.mean_pose = WeightedMeanPose(particles_);
  map_.InsertScan(scan, step.best_pose);

  step.neff = EffectiveSampleSize(weights);
  if (step.neff < options_.resample_neff_ratio * options_.num_particles) {
    const std::vector<int> keep = Resample(weights, options_.resampling, rng_);
    std::vector<Particle> resampled;
    resampled.reserve(particles_.size());
    const double uniform = 1.0 / options_.num_particles;
    for (const int k : keep)
      resampled.push_back(Particle{particles_[static_cast<std::size_t>(k)].pose, uniform});
    particles_ = std::move(resampled);
    std::fill(log_weights_.begin(), log_weights_.end(), 0.0);
    step.resampled = true;
    ++resample_count_;
  }
  last_step_ = step;
  return step;
}

}  // namespace slamrig::slam
