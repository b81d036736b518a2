#include "slam/pipeline/particle_filter_estimator.h"

namespace slamrig::slam {

ParticleFilterOptions ParticleFilterEstimator::Seeded(ParticleFilterOptions options,
                                                      std::uint64_t seed) {
  options.seed = seed;
  return options;
}

ParticleFilterEstimator::ParticleFilterEstimator(const ParticleFilterOptions& options,
                                                 const EstimatorContext& context)
    : filter_(Seeded(options, context.seed)) {}

ScanEstimate ParticleFilterEstimator::AddScan(const SyncedScan& scan) {
  const ParticleFilterStep step = filter_.AddScan(scan.scan, scan.increment);
  neff_sum_ += step.neff;
  ++scans_;
  updates_ += step.updated;
  return {step.best_pose, step.mean_pose, {{"neff", step.neff}}, std::nullopt};
}

std::map<std::string, double> ParticleFilterEstimator::Statistics() const {
  return {{"mean_neff", scans_ > 0 ? neff_sum_ / scans_ : 0.0},
          {"resamples", filter_.resample_count()},
          {"updates", updates_}};
}

EstimatorView ParticleFilterEstimator::View() const {
  EstimatorView view;
  view.particles.reserve(filter_.particles().size());
  for (const Particle& p : filter_.particles()) view.particles.push_back({p.pose, p.weight});
  return view;
}

}  // namespace slamrig::slam
