#pragma once

#include <cmath>

#include "slam/pf/particle_filter.h"
#include "slam/pf/particle_filter_options.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/health.h"
#include "slam/pipeline/revisits.h"

namespace slamrig::slam {

/// The particle filter (slam/pf) behind the Estimator interface: the best particle is the
/// online pose, the weighted mean the second estimate, Neff the per-scan trace.
class ParticleFilterEstimator final : public Estimator {
 public:
  /// `context.seed` replaces `options.seed`.
  ParticleFilterEstimator(const ParticleFilterOptions& options, const EstimatorContext& context);

  ScanEstimate AddScan(const SyncedScan& scan) override;
  /// The map check (CheckRevisits) on the online poses.
  void Finish() override;
  const OccupancyGrid& map() const override { return filter_.map(); }
  /// mean_neff (over scans), resamples, updates (scans the filter ran on, not just odometry);
  /// lost and relocalisations (counts), lost_at_s and relocalised_at_s (the first loss and the
  /// first relocalisation after it, seconds since the first scan; NaN when none); revisits,
  /// revisits_disagreeing and revisits_disagreeing_places (the map check's, after Finish());
  /// diverged (Diverged()).
  std::map<std::string, double> Statistics() const override;
  /// The names Statistics() reports, without an instance: the algorithm table's list (and so
  /// the expectations'); EstimatorRunner checks every run's Statistics() against it.
  static const std::vector<std::string>& StatisticNames();
  EstimatorView View() const override;

 private:
  // Lost at the end or on more than kDivergedLostShare of the scans, the estimate contradicted
  // the wheels (WheelCheck::Diverged), or its map itself where it came back (the map check).
  bool Diverged() const;
  static ParticleFilterOptions Seeded(ParticleFilterOptions options, std::uint64_t seed);

  ParticleFilter filter_;
  double neff_sum_ = 0.0;
  int scans_ = 0;
  int updates_ = 0;
  Time start_;
  bool was_lost_ = false;
  double lost_at_s_ = NAN;
  double relocalised_at_s_ = NAN;
  HealthRecord health_;
  WheelCheck wheels_;
  Pose2 previous_estimate_;
  std::vector<Pose2> online_;  // per scan
  RevisitViews views_;
  RevisitAgreement revisits_;  // at Finish()
};

}  // namespace slamrig::slam
