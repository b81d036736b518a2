#include "slam/pf/particle_filter_options.h"

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> RelocalisationOptions::Validate() const {
  Rules rules;
  rules.InUnitInterval("fast_rate", fast_rate)
      .InUnitInterval("slow_rate", slow_rate)
      .InUnitInterval("lost_ratio", lost_ratio)
      .InUnitInterval("accept_ratio", accept_ratio)
      .Require(slow_rate <= fast_rate, "slow_rate", slow_rate, "must be <= fast_rate")
      .AtLeast("warmup_updates", warmup_updates, 1)
      .Positive("confirm_distance_m", confirm_distance_m)
      .Positive("confirm_angle_rad", confirm_angle_rad)
      .NonNegative("win_margin", win_margin)
      .Positive("slip_radius_m", slip_radius_m)
      .Positive("slip_angle_rad", slip_angle_rad)
      .NonNegative("odometry_gap_s", odometry_gap_s)
      .NonNegative("scan_matched_search_m", scan_matched_search_m)
      .AtLeast("confirm_updates", confirm_updates, 1)
      .AtLeast("global_candidates", global_candidates, 1)
      .Positive("distinct_radius_m", distinct_radius_m)
      .Positive("distinct_angle_rad", distinct_angle_rad)
      .NonNegative("ambiguity_margin", ambiguity_margin)
      .AtLeast("resume_updates", resume_updates, 1)
      .Positive("search_max_range_m", search_max_range_m)
      .Positive("search_resolution_m", search_resolution_m)
      .Positive("search_window_m", search_window_m)
      .Positive("max_lost_s", max_lost_s)
      .NonNegative("reset_sigma_xy_m", reset_sigma_xy_m)
      .NonNegative("reset_sigma_yaw_rad", reset_sigma_yaw_rad);
  return rules.errors();
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
  Rules rules;
  rules.Positive("particles", num_particles)
      .NonNegative("sigma_xy_m", sigma_xy_m)
      .NonNegative("sigma_yaw_rad", sigma_yaw_rad)
      .Positive("observation_scale", observation_scale)
      .NonNegative("unimodal_radius_m", unimodal_radius_m)
      .NonNegative("unimodal_yaw_rad", unimodal_yaw_rad)
      .Fraction("resample_neff_ratio", resample_neff_ratio)
      .NonNegative("min_update_distance_m", min_update_distance_m)
      .NonNegative("min_update_angle_rad", min_update_angle_rad)
      .Require(degeneracy_ratio >= 0.0 && degeneracy_ratio < 1.0, "degeneracy_ratio",
               degeneracy_ratio, "must be in [0, 1)")
      .Require(max_incidence_rad > 0.0 && max_incidence_rad <= 1.5707963267948966,
               "max_incidence_rad", max_incidence_rad, "must be in (0, pi/2]")
      .InRange("threads", num_threads, 0, 1024);
  rules.Nested("rot_trans_rot", rot_trans_rot.Validate())
      .Nested("odometry_calibration", odometry_calibration.Validate())
      .Nested("points", points.Validate())
      .Nested("correlation", correlation.Validate())
      .Nested("likelihood_field", likelihood_field.Validate())
      .Nested("adaptive_sigma", adaptive_sigma.Validate());
  const double max_window_m = likelihood_field.cutoff_sigmas * adaptive_sigma.min_m * (1 + 1e-9);
  rules.Require(!(adaptive_sigma.enabled && adaptive_sigma.window_m > max_window_m),
                "adaptive_sigma.window_m", adaptive_sigma.window_m,
                "must be <= likelihood_field.cutoff_sigmas x adaptive_sigma.min_m");
  rules.Nested("refiner", refiner.Validate()).Nested("relocalisation", relocalisation.Validate());
  if (observation == ObservationModel::kLikelihoodField &&
      correlation.value != CorrelationValue::kRawValue) {
    rules.Add("correlation.value = occupied; must be log_odds with the likelihood field");
  }
  if (adaptive_sigma.enabled && observation != ObservationModel::kLikelihoodField) {
    rules.Add(
        "adaptive_sigma.enabled = true; needs observation = likelihood_field (or set it false)");
  }
  if (refine && !move_to_best_shift) rules.Add("refine = true; needs move_to_best_shift = true");
  rules.Nested("map", map.Validate());
  return rules.errors();
}

}  // namespace slamrig::slam
