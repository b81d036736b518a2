#pragma once

#include <utility>
#include <vector>

#include "slam/pf/rbpf.h"
#include "slam/pf/rbpf_options.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/health.h"
#include "slam/pipeline/revisits.h"

namespace slamrig::slam {

/// The Rao-Blackwellised particle filter (slam/pf/rbpf.h) behind the Estimator interface: the
/// online pose is the particle with the most likely path, its map the map, and its whole path
/// the revised trajectory (an RBPF revises its past when resampling drops other paths).
class RbpfEstimator final : public Estimator {
 public:
  /// `context.seed` replaces `options.seed`.
  RbpfEstimator(const RbpfOptions& options, const EstimatorContext& context);

  ScanEstimate AddScan(const SyncedScan& scan) override;
  /// The map check (CheckRevisits) on the revised poses.
  void Finish() override;
  std::optional<std::vector<Pose2>> RevisedPoses() const override;
  /// The best particle's map, converted when asked for after it changed.
  const OccupancyGrid& map() const override;
  /// mean_neff, resamples, updates, failed_matches (particle matches that fell back on the
  /// odometry), odometry_rejections (updates whose increment the odometry check replaced),
  /// mean_weight_exponent (the weights' exponent, RbpfStep::weight_exponent, over updates),
  /// map_tiles (distinct tiles over all particles at the end) and map_tiles_per_particle;
  /// map_witnesses and map_contradiction_m (the witness check's, Rbpf::MapContradictionM);
  /// revisits, revisits_disagreeing and revisits_disagreeing_places (the map check's, after
  /// Finish()); lost (losses) and diverged.
  std::map<std::string, double> Statistics() const override;
  /// The names Statistics() reports, without an instance: the algorithm table's list (and so
  /// the expectations'); EstimatorRunner checks every run's Statistics() against it.
  static const std::vector<std::string>& StatisticNames();
  EstimatorView View() const override;

 private:
  // Lost at the end or on more than kDivergedLostShare of the scans, the estimate contradicted
  // the wheels (WheelCheck::Diverged), or the best path its own map by more than kDivergedErrorM
  // (Rbpf::MapContradictionM), or the final map contradicts itself where the robot came back.
  bool Diverged() const;
  static RbpfOptions Seeded(RbpfOptions options, std::uint64_t seed);

  Rbpf filter_;
  // Per scan: the update it follows and the odometry since that update.
  std::vector<std::pair<int, Pose2>> scan_offsets_;
  Pose2 offset_;
  double neff_sum_ = 0.0;
  int updates_ = 0;
  double exponent_sum_ = 0.0;
  int failed_matches_ = 0;
  // The lost rule: the best particle's matched fraction against its own long-term level.
  QualityRatio matched_ratio_{0.3, 0.02, 20, 0.5};
  bool lost_ = false;         // at the last update; held between updates
  double see_through_ = 0.0;  // at the last update
  WallCrossings wall_crossings_;
  HealthRecord health_;
  WheelCheck wheels_;
  RevisitViews views_;
  RevisitAgreement revisits_;  // at Finish()
  mutable OccupancyGrid map_;
  mutable int map_version_ = -1;  // update count the map was converted at
};

}  // namespace slamrig::slam
