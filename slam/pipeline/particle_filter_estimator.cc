#include "slam/pipeline/particle_filter_estimator.h"

#include <cmath>

#include "slam/matching/scan_points.h"

namespace slamrig::slam {

ParticleFilterOptions ParticleFilterEstimator::Seeded(ParticleFilterOptions options,
                                                      std::uint64_t seed) {
  options.seed = seed;
  return options;
}

ParticleFilterEstimator::ParticleFilterEstimator(const ParticleFilterOptions& options,
                                                 const EstimatorContext& context)
    : filter_(Seeded(options, context.seed)),
      wheels_(context.own_odometry, filter_.options().points) {
  filter_.SetScanMatchedIncrements(!context.own_odometry);
}

ScanEstimate ParticleFilterEstimator::AddScan(const SyncedScan& scan) {
  const ParticleFilterStep step = filter_.AddScan(scan.scan, scan.increment, scan.odometry_gap_s);
  if (scans_ == 0) start_ = scan.scan.time;
  neff_sum_ += step.neff;
  ++scans_;
  updates_ += step.updated;
  // The events, in data time since the first scan: the first loss and the first recovery after.
  const double t = SecondsBetween(scan.scan.time, start_);
  if (step.lost && !was_lost_ && std::isnan(lost_at_s_)) lost_at_s_ = t;
  if (step.relocalised && !std::isnan(lost_at_s_) && std::isnan(relocalised_at_s_)) {
    relocalised_at_s_ = t;
  }
  was_lost_ = step.lost;
  // Lost by the filter's own test (the short-term average of the match quality below lost_ratio
  // times its long-term one, ParticleFilterOptions::relocalisation), or the estimate's motion
  // contradicts the wheels' (WheelAgreement); a relocalisation, a gap in the odometry or a
  // search after one moves the estimate on purpose and restarts that comparison.
  if (step.relocalised || step.gap_corrected ||
      scan.odometry_gap_s > filter_.options().relocalisation.odometry_gap_s) {
    wheels_.Reset();
  }
  const bool contradicts = wheels_.Judge(scan.scan, scan.increment,
                                         previous_estimate_.Between(step.best_pose), step.updated);
  previous_estimate_ = step.best_pose;
  online_.push_back(step.best_pose);
  if (views_.Offer(step.best_pose)) {
    views_.Keep(ScanToBasePoints(scan.scan, filter_.options().points));
  }
  const bool lost = step.lost || contradicts;
  ScanEstimate estimate{step.best_pose,
                        step.mean_pose,
                        {{"neff", step.neff}, {"match_quality", step.quality}},
                        std::nullopt,
                        lost};
  wheels_.AppendTrace(&estimate.trace);
  estimate.trace.push_back({"lost", lost ? 1.0 : 0.0});
  health_.Add(lost);
  if (filter_.options().adaptive_sigma.enabled) {
    estimate.trace.push_back({"field_sigma_m", filter_.field_sigma_m()});
  }
  return estimate;
}

void ParticleFilterEstimator::Finish() { revisits_ = views_.Check(online_); }

const std::vector<std::string>& ParticleFilterEstimator::StatisticNames() {
  static const std::vector<std::string> names =
      RevisitAgreement::WithStatisticNames(WheelCheck::WithStatisticNames(
          {"mean_neff", "resamples", "updates", "lost", "relocalisations", "resumed", "lost_at_s",
           "relocalised_at_s", "field_sigma_m", "wall_distance_m", "diverged", "gap_corrections"}));
  return names;
}

std::map<std::string, double> ParticleFilterEstimator::Statistics() const {
  std::map<std::string, double> statistics = {{"mean_neff", scans_ > 0 ? neff_sum_ / scans_ : 0.0},
                                              {"resamples", filter_.resample_count()},
                                              {"updates", updates_},
                                              {"lost", filter_.lost_count()},
                                              {"relocalisations", filter_.relocalisation_count()},
                                              {"resumed", filter_.resumed_count()},
                                              {"lost_at_s", lost_at_s_},
                                              {"gap_corrections", filter_.gap_correction_count()},
                                              {"relocalised_at_s", relocalised_at_s_},
                                              {"field_sigma_m", filter_.field_sigma_m()},
                                              {"wall_distance_m", filter_.wall_distance_m()},
                                              {"diverged", Diverged() ? 1.0 : 0.0}};
  wheels_.AppendStatistics(&statistics);
  revisits_.AppendStatistics(&statistics);
  return statistics;
}

bool ParticleFilterEstimator::Diverged() const {
  return health_.Diverged() || wheels_.Diverged() || revisits_.contradicts({});
}

EstimatorView ParticleFilterEstimator::View() const {
  EstimatorView view;
  view.particles.reserve(filter_.particles().size());
  for (const Particle& p : filter_.particles()) view.particles.push_back({p.pose, p.weight});
  return view;
}

}  // namespace slamrig::slam
