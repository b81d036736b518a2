#include "slam/pipeline/rbpf_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/grid/see_through.h"
#include "slam/matching/scan_points.h"
#include "slam/types/check.h"

namespace slamrig::slam {

RbpfOptions RbpfEstimator::Seeded(RbpfOptions options, std::uint64_t seed) {
  options.seed = seed;
  return options;
}

RbpfEstimator::RbpfEstimator(const RbpfOptions& options, const EstimatorContext& context)
    : filter_(Seeded(options, context.seed)),
      wheels_(context.own_odometry, filter_.options().points),
      map_(options.map) {
  filter_.SetScanMatchedIncrements(!context.own_odometry);
}

ScanEstimate RbpfEstimator::AddScan(const SyncedScan& scan) {
  const RbpfStep step = filter_.AddScan(scan.scan, scan.increment, scan.odometry_gap_s);
  // The best particle's own motion since the previous scan: from where its own path put the
  // previous scan (its pose at the previous update, moved by the odometry since) at an update,
  // the odometry between updates. Not the step from the previous best particle to this one: a
  // switch of particles revises the path, it is not motion.
  Pose2 estimate_increment = scan.increment;
  if (step.updated && !filter_.particles().empty() && filter_.best().history &&
      filter_.best().history->parent) {
    estimate_increment = (filter_.best().history->parent->pose * offset_).Between(step.best_pose);
  }
  offset_ = step.updated ? Pose2() : offset_ * scan.increment;
  scan_offsets_.emplace_back(filter_.update_count() - 1, offset_);
  neff_sum_ += step.neff;
  updates_ += step.updated;
  failed_matches_ += step.failed_matches;
  if (step.updated) exponent_sum_ += step.weight_exponent;
  // Lost: the best particle's matched fraction, averaged over the last few updates, below half
  // its long-term level (the pf's lost_ratio rule on the RBPF's own quality), or the estimate's
  // motion contradicts the wheels' (WheelAgreement). A gap in the odometry, or the filter's own
  // odometry check replacing the wheels' increment, restarts that comparison.
  if (step.updated) lost_ = matched_ratio_.Add(step.matched_fraction) < kLostRatio;
  if (step.odometry_rejected || scan.odometry_gap_s > filter_.options().odometry_gap_s) {
    wheels_.Reset();
  }
  // The best map against its own scan: the share of its rays crossing a wall the map holds, and
  // the extent of wall crossed over the last updates (WallCrossings: what a map written twice
  // shows). Health values, not judged (docs/studies/see-through.md).
  if (step.updated && !filter_.particles().empty()) {
    const TiledGrid& best_map = filter_.best().map;
    std::vector<Eigen::Array2i> cells;
    see_through_ = CountSeeThrough(best_map, scan.scan, step.best_pose,
                                   SparseScanRange(scan.scan, filter_.options().points), {}, &cells)
                       .fraction();
    std::vector<Eigen::Vector2d> crossed;
    crossed.reserve(cells.size());
    for (const Eigen::Array2i& cell : cells) crossed.push_back(best_map.CellCenter(cell));
    wall_crossings_.Add(crossed);
  }
  const bool contradicts =
      wheels_.Judge(scan.scan, scan.increment, estimate_increment, step.updated);
  if (views_.Offer(step.best_pose)) {
    views_.Keep(ScanToBasePoints(scan.scan, filter_.options().points));
  }
  health_.Add(lost_ || contradicts);
  const double particles =
      static_cast<double>(std::max<std::size_t>(filter_.particles().size(), 1));
  ScanEstimate estimate{step.best_pose,
                        step.mean_pose,
                        {{"neff", step.neff},
                         {"neff_ratio", step.neff / particles},
                         {"matched_fraction", step.matched_fraction},
                         {"matched_fraction_ratio", matched_ratio_.ratio()},
                         {"failed_match_share", step.failed_matches / particles},
                         {"see_through_fraction", see_through_},
                         {"wall_crossed_m", wall_crossings_.extent_m()},
                         {"map_contradiction_m", step.map_contradiction_m}},
                        std::nullopt,
                        lost_ || contradicts};
  wheels_.AppendTrace(&estimate.trace);
  return estimate;
}

void RbpfEstimator::Finish() { revisits_ = views_.Check(*RevisedPoses()); }

std::optional<std::vector<Pose2>> RbpfEstimator::RevisedPoses() const {
  const std::vector<Pose2> updates = filter_.BestUpdatePoses();
  std::vector<Pose2> poses;
  poses.reserve(scan_offsets_.size());
  for (const auto& [update, offset] : scan_offsets_) {
    SLAMRIG_CHECK(update >= 0 && static_cast<std::size_t>(update) < updates.size(),
                  "rbpf: a scan follows an update the best path does not hold");
    poses.push_back(updates[static_cast<std::size_t>(update)] * offset);
  }
  return poses;
}

const OccupancyGrid& RbpfEstimator::map() const {
  if (map_version_ != filter_.update_count() && !filter_.particles().empty()) {
    map_ = filter_.best().map.ToOccupancyGrid();
    map_version_ = filter_.update_count();
  }
  return map_;
}

const std::vector<std::string>& RbpfEstimator::StatisticNames() {
  static const std::vector<std::string> names =
      RevisitAgreement::WithStatisticNames(WheelCheck::WithStatisticNames(
          {"mean_neff", "resamples", "updates", "failed_matches", "odometry_rejections",
           "gap_corrections", "mean_weight_exponent", "map_tiles", "map_tiles_per_particle",
           "wall_crossed_m", "map_witnesses", "map_contradiction_m", "lost", "diverged"}));
  return names;
}

std::map<std::string, double> RbpfEstimator::Statistics() const {
  const int scans = static_cast<int>(scan_offsets_.size());
  const int tiles = filter_.particles().empty() ? 0 : filter_.DistinctTiles();
  std::map<std::string, double> statistics = {
      {"mean_neff", scans > 0 ? neff_sum_ / scans : 0.0},
      {"resamples", filter_.resample_count()},
      {"updates", updates_},
      {"failed_matches", failed_matches_},
      {"odometry_rejections", filter_.odometry_rejections()},
      {"gap_corrections", filter_.gap_corrections()},
      {"mean_weight_exponent", updates_ > 0 ? exponent_sum_ / updates_ : 0.0},
      {"map_tiles", tiles},
      {"map_tiles_per_particle",
       filter_.particles().empty()
           ? 0.0
           : static_cast<double>(tiles) / static_cast<double>(filter_.particles().size())},
      {"wall_crossed_m", wall_crossings_.worst_m()},
      {"map_witnesses", static_cast<double>(filter_.map_witnesses().size())},
      {"map_contradiction_m", filter_.MapContradictionM()},
      {"lost", health_.losses()},
      {"diverged", Diverged() ? 1.0 : 0.0}};
  wheels_.AppendStatistics(&statistics);
  revisits_.AppendStatistics(&statistics);
  return statistics;
}

bool RbpfEstimator::Diverged() const {
  return health_.Diverged() || wheels_.Diverged() ||
         filter_.MapContradictionM() > kDivergedErrorM || revisits_.contradicts({});
}

EstimatorView RbpfEstimator::View() const {
  EstimatorView view;
  const std::vector<RbpfParticle>& particles = filter_.particles();
  if (particles.empty()) return view;
  double max_log = -std::numeric_limits<double>::infinity();
  for (const RbpfParticle& p : particles) max_log = std::max(max_log, p.log_weight);
  double total = 0.0;
  for (const RbpfParticle& p : particles) total += std::exp(p.log_weight - max_log);
  for (const RbpfParticle& p : particles)
    view.particles.push_back({p.pose, std::exp(p.log_weight - max_log) / total});
  return view;
}

}  // namespace slamrig::slam
