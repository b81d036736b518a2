#include "slam/pf/particle_filter_options.h"

#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

template <typename T>
std::string Rule(const char* field, T value, const char* rule) {
  return RuleViolation(field, value, rule);
}

void Prefixed(const char* key, const std::vector<std::string>& from, std::vector<std::string>& to) {
  AppendErrors(&to, PrefixErrors(key, from));
}

}  // namespace

ParticleFilterOptions ParticleFilterOptions::ReportsPreset() {
  ParticleFilterOptions o;
  o.motion_noise = MotionNoiseModel::kGaussianPerStep;
  o.sigma_xy_m = 0.005;
  o.sigma_yaw_rad = 0.003;
  o.observation = ObservationModel::kMapCorrelation;
  o.points = ScanPointsOptions{0.1, 30.0, 1, 0.0};
  o.correlation = MapCorrelatorOptions{4, 0, 0.01, CorrelationValue::kOccupiedIndicator, 0.0f};
  o.observation_scale = 1.0;
  o.move_to_best_shift = false;
  o.refine = false;
  o.resampling = ResamplingScheme::kStratified;
  o.resample_neff_ratio = 0.5;
  // 80 % trust: +log 4 on hits, -log 4 on free cells, every beam counts.
  o.map.hit_log_odds = 1.3862944f;
  o.map.miss_log_odds = -1.3862944f;
  o.map.min_log_odds = -10.0f;
  o.map.max_log_odds = 10.0f;
  o.map.update_once_per_scan = false;
  o.min_update_distance_m = 0.0;
  o.min_update_angle_rad = 0.0;
  return o;
}

std::vector<std::string> ParticleFilterOptions::Validate() const {
  std::vector<std::string> errors;
  if (num_particles <= 0) errors.push_back(Rule("particles", num_particles, "must be > 0"));
  if (!(sigma_xy_m >= 0.0)) errors.push_back(Rule("sigma_xy_m", sigma_xy_m, "must be >= 0"));
  if (!(sigma_yaw_rad >= 0.0))
    errors.push_back(Rule("sigma_yaw_rad", sigma_yaw_rad, "must be >= 0"));
  if (!(observation_scale > 0.0)) {
    errors.push_back(Rule("observation_scale", observation_scale, "must be > 0"));
  }
  if (!(resample_neff_ratio >= 0.0 && resample_neff_ratio <= 1.0)) {
    errors.push_back(Rule("resample_neff_ratio", resample_neff_ratio, "must be in [0, 1]"));
  }
  if (!(min_update_distance_m >= 0.0)) {
    errors.push_back(Rule("min_update_distance_m", min_update_distance_m, "must be >= 0"));
  }
  if (!(min_update_angle_rad >= 0.0)) {
    errors.push_back(Rule("min_update_angle_rad", min_update_angle_rad, "must be >= 0"));
  }
  if (num_threads < 1) errors.push_back(Rule("threads", num_threads, "must be >= 1"));
  Prefixed("rot_trans_rot", rot_trans_rot.Validate(), errors);
  Prefixed("points", points.Validate(), errors);
  Prefixed("correlation", correlation.Validate(), errors);
  Prefixed("likelihood_field", likelihood_field.Validate(), errors);
  Prefixed("refiner", refiner.Validate(), errors);
  if (observation == ObservationModel::kLikelihoodField &&
      correlation.value != CorrelationValue::kRawValue) {
    errors.push_back("correlation.value = occupied; must be log_odds with the likelihood field");
  }
  if (refine && !move_to_best_shift) {
    errors.push_back("refine = true; needs move_to_best_shift = true");
  }
  Prefixed("map", map.Validate(), errors);
  return errors;
}

}  // namespace slamrig::slam
