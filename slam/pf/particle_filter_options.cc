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

std::vector<std::string> RelocalisationOptions::Validate() const {
  std::vector<std::string> errors;
  auto in_unit = [&](const char* field, double v) {
    if (!(v > 0.0 && v <= 1.0)) errors.push_back(Rule(field, v, "must be in (0, 1]"));
  };
  auto positive = [&](const char* field, double v) {
    if (!(v > 0.0)) errors.push_back(Rule(field, v, "must be > 0"));
  };
  in_unit("fast_rate", fast_rate);
  in_unit("slow_rate", slow_rate);
  in_unit("lost_ratio", lost_ratio);
  in_unit("accept_ratio", accept_ratio);
  if (!(slow_rate <= fast_rate)) {
    errors.push_back(Rule("slow_rate", slow_rate, "must be <= fast_rate"));
  }
  if (warmup_updates < 1) errors.push_back(Rule("warmup_updates", warmup_updates, "must be >= 1"));
  positive("confirm_distance_m", confirm_distance_m);
  positive("confirm_angle_rad", confirm_angle_rad);
  if (!(win_margin >= 0.0)) errors.push_back(Rule("win_margin", win_margin, "must be >= 0"));
  positive("slip_radius_m", slip_radius_m);
  positive("slip_angle_rad", slip_angle_rad);
  if (confirm_updates < 1) {
    errors.push_back(Rule("confirm_updates", confirm_updates, "must be >= 1"));
  }
  if (global_candidates < 1) {
    errors.push_back(Rule("global_candidates", global_candidates, "must be >= 1"));
  }
  positive("distinct_radius_m", distinct_radius_m);
  positive("distinct_angle_rad", distinct_angle_rad);
  if (!(ambiguity_margin >= 0.0)) {
    errors.push_back(Rule("ambiguity_margin", ambiguity_margin, "must be >= 0"));
  }
  if (resume_updates < 1) errors.push_back(Rule("resume_updates", resume_updates, "must be >= 1"));
  positive("search_max_range_m", search_max_range_m);
  positive("search_resolution_m", search_resolution_m);
  positive("search_window_m", search_window_m);
  positive("max_lost_s", max_lost_s);
  if (!(reset_sigma_xy_m >= 0.0)) {
    errors.push_back(Rule("reset_sigma_xy_m", reset_sigma_xy_m, "must be >= 0"));
  }
  if (!(reset_sigma_yaw_rad >= 0.0)) {
    errors.push_back(Rule("reset_sigma_yaw_rad", reset_sigma_yaw_rad, "must be >= 0"));
  }
  return errors;
}

ParticleFilterOptions ParticleFilterOptions::ReportsPreset() {
  ParticleFilterOptions o;
  o.motion_noise = MotionNoiseModel::kGaussianPerStep;
  o.sigma_xy_m = 0.005;
  o.sigma_yaw_rad = 0.003;
  o.observation = ObservationModel::kMapCorrelation;
  o.points = ScanPointsOptions{
      .min_range_m = 0.1, .max_range_m = 30.0, .beam_stride = 1, .voxel_size_m = 0.0};
  o.correlation = MapCorrelatorOptions{.xy_half_width_cells = 4,
                                       .yaw_half_steps = 0,
                                       .yaw_step_rad = 0.01,
                                       .value = CorrelationValue::kOccupiedIndicator,
                                       .occupied_threshold = 0.0f};
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
  o.degeneracy_ratio = 0.0;
  o.unimodal_radius_m = 0.0;         // the best particle, as in the reports
  o.adaptive_sigma.enabled = false;  // there is no likelihood field to sharpen
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
  if (!(unimodal_radius_m >= 0.0)) {
    errors.push_back(Rule("unimodal_radius_m", unimodal_radius_m, "must be >= 0"));
  }
  if (!(unimodal_yaw_rad >= 0.0)) {
    errors.push_back(Rule("unimodal_yaw_rad", unimodal_yaw_rad, "must be >= 0"));
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
  if (!(degeneracy_ratio >= 0.0 && degeneracy_ratio < 1.0)) {
    errors.push_back(Rule("degeneracy_ratio", degeneracy_ratio, "must be in [0, 1)"));
  }
  if (!(max_incidence_rad > 0.0 && max_incidence_rad <= 1.5707963267948966)) {
    errors.push_back(Rule("max_incidence_rad", max_incidence_rad, "must be in (0, pi/2]"));
  }
  if (num_threads < 1) errors.push_back(Rule("threads", num_threads, "must be >= 1"));
  Prefixed("rot_trans_rot", rot_trans_rot.Validate(), errors);
  Prefixed("odometry_calibration", odometry_calibration.Validate(), errors);
  Prefixed("points", points.Validate(), errors);
  Prefixed("correlation", correlation.Validate(), errors);
  Prefixed("likelihood_field", likelihood_field.Validate(), errors);
  Prefixed("adaptive_sigma", adaptive_sigma.Validate(), errors);
  if (adaptive_sigma.enabled && adaptive_sigma.window_m > likelihood_field.cutoff_sigmas *
                                                              adaptive_sigma.min_m * (1 + 1e-9)) {
    errors.push_back(Rule("adaptive_sigma.window_m", adaptive_sigma.window_m,
                          "must be <= likelihood_field.cutoff_sigmas x adaptive_sigma.min_m"));
  }
  Prefixed("refiner", refiner.Validate(), errors);
  Prefixed("relocalisation", relocalisation.Validate(), errors);

  if (observation == ObservationModel::kLikelihoodField &&
      correlation.value != CorrelationValue::kRawValue) {
    errors.push_back("correlation.value = occupied; must be log_odds with the likelihood field");
  }
  if (adaptive_sigma.enabled && observation != ObservationModel::kLikelihoodField) {
    errors.push_back(
        "adaptive_sigma.enabled = true; needs observation = likelihood_field (or set it false)");
  }
  if (refine && !move_to_best_shift) {
    errors.push_back("refine = true; needs move_to_best_shift = true");
  }
  Prefixed("map", map.Validate(), errors);
  return errors;
}

}  // namespace slamrig::slam
