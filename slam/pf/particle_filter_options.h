#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/adaptive_field_sigma.h"
#include "slam/matching/likelihood_field.h"
#include "slam/matching/map_correlator.h"
#include "slam/matching/scan_points.h"
#include "slam/matching/scan_refiner.h"
#include "slam/odometry/odometry_calibration.h"
#include "slam/odometry/rot_trans_rot_model.h"
#include "slam/pf/resampling.h"

namespace slamrig::slam {

/// How each particle's motion is perturbed in the prediction step.
enum class MotionNoiseModel {
  /// Odometry increment plus zero-mean Gaussian noise on x, y and yaw with fixed standard
  /// deviations per scan step (the w terms of Wang's Eq. 6).
  kGaussianPerStep,
  /// Rotation-translation-rotation with alpha noise (Probabilistic Robotics, Table 5.6): the
  /// spread grows with the motion, so one setting fits 40 Hz logs and 0.5 m CARMEN steps alike.
  kRotTransRot,
};

/// How a particle's scan is scored against the map.
enum class ObservationModel {
  kMapCorrelation,   ///< the reports' correlation with the thresholded map (Wang, Eq. 7)
  kLikelihoodField,  ///< sum of likelihood-field log-likelihoods (Probabilistic Robotics, 6.4)
};

/// Lost-filter detection and global relocalisation against the map built so far (Thrun et al.,
/// Probabilistic Robotics, Table 8.3, augmented MCL: short- and long-term averages of the
/// measurement likelihood; the global search is the branch-and-bound correlative matcher of Hess
/// et al. 2016). The match quality of an update is the best particle's score over the points
/// divided by the likelihood field's maximum, in [0, 1].
struct RelocalisationOptions {
  /// On by default. The lost test is made only when most of the scan lands on observed map cells
  /// (new ground says nothing). While lost the filter goes on tracking (only the map is frozen),
  /// and a loss ends in a relocalisation only when a place elsewhere fits clearly better than
  /// anything near the filter on confirm_updates updates in a row, followed through the odometry;
  /// otherwise tracking resumes. Only the likelihood-field observation model has a quality in
  /// [0, 1] to watch.
  bool enabled = true;
  /// alpha_fast of the short-term average of the quality: 1 reacts to the first bad scan (a
  /// kidnapped filter soon fits the scan somewhere near by, in a self-similar building, and the dip
  /// is gone).
  double fast_rate = 1.0;
  double slow_rate = 0.02;  ///< alpha_slow of the long-term average
  double lost_ratio = 0.5;  ///< lost when the short-term average < this x the long-term one
  int warmup_updates = 20;  ///< updates before the long-term average is trusted
  /// A match (near or global) counts as a place when its quality reaches this x the long-term
  /// average from before the loss; a tracked hypothesis that does is fitting as usual again.
  double accept_ratio = 0.8;
  /// A candidate found on one update is followed to the next by the odometry and matched
  /// locally there; moved by more than this, it did not explain the scan where the odometry put
  /// it, and is dropped.
  double confirm_distance_m = 0.3;
  double confirm_angle_rad = 0.1;
  /// A place elsewhere must beat the tracked hypothesis (the filter's best particle, or the best
  /// place within slip_radius_m and slip_angle_rad of it) by this fraction of the long-term
  /// quality, on this many lost updates in a row, followed through the odometry, before the cloud
  /// is put there.
  double win_margin = 0.1;
  int confirm_updates = 2;
  /// The global search returns this many distinct places (non-maximum suppression: apart by more
  /// than distinct_radius_m in x and y or distinct_angle_rad in heading), and each is followed
  /// through the odometry like the one before: in a building whose rooms repeat, the best place
  /// on a frozen map may be the neighbouring bay by a few per cent.
  int global_candidates = 3;
  double distinct_radius_m = 1.0;
  double distinct_angle_rad = 0.5;
  /// The winning place must also beat every other distinct place of the update (followed or just
  /// found) by this fraction of the long-term quality; while two fit alike the filter stays lost
  /// and waits for a scan that tells them apart (or for max_lost_s).
  double ambiguity_margin = 0.05;
  /// Lost updates in a row on which no place elsewhere wins after which tracking resumes where
  /// the filter is, however poorly it fits there: no evidence for a kidnapping came.
  int resume_updates = 2;
  /// A place within this of the tracked one that fits better than it (and nothing elsewhere
  /// clearly better still) is the odometry slipping by more than the shift search covers, not a
  /// kidnapping: the cloud is moved there and tracking resumes.
  double slip_radius_m = 1.0;
  double slip_angle_rad = 0.6;  ///< and headings within this of the tracked one
  /// The odometry went silent for longer than this before an update (a gap in the log,
  /// SyncedScan::odometry_gap_s): the robot may have turned through it while the increment held
  /// still. That update also searches within slip_radius_m at every heading, and the cloud moves
  /// to the place found when it fits as a place (accept_ratio) and beats the filter's own match
  /// by win_margin. 0: never.
  double odometry_gap_s = 1.0;
  /// Where the increments are scan matches (a source without odometry: ScanMatchedOdometry,
  /// whose failures are a corridor's or a room's aliases anywhere within its search window, up to
  /// 2 m, not a wheel's slip), every update searches within this of the estimate at every heading
  /// as after a gap, and the cloud moves to the place found on the same terms. 0: never.
  double scan_matched_search_m = 2.0;
  double search_max_range_m = 10.0;  ///< points used by the global search (a finer yaw step)
  /// The global search's raster: the map max-pooled to this (rounded to a whole number of map
  /// cells, at least one), each place it finds then matched at the map's resolution (the shift
  /// search and refinement that tracking uses). The search's cost falls with the cube of the
  /// ratio (translations in x and y, and headings, whose step follows the resolution).
  double search_resolution_m = 0.2;
  /// The global search covers x and y within this of where the filter was lost (all of a
  /// building's floor; it bounds the cost on a city-sized map), every heading.
  double search_window_m = 20.0;
  /// Lost this long (data time) without a confirmed match: the robot is taken to be somewhere
  /// new, and the filter maps on from its odometry.
  double max_lost_s = 30.0;
  double reset_sigma_xy_m = 0.02;      ///< particles are redrawn around the match with this
  double reset_sigma_yaw_rad = 0.005;  ///< spread

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of RelocalisationOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, RelocalisationOptions& o) {
  v("enabled", o.enabled);
  v("fast_rate", o.fast_rate);
  v("slow_rate", o.slow_rate);
  v("lost_ratio", o.lost_ratio);
  v("warmup_updates", o.warmup_updates);
  v("accept_ratio", o.accept_ratio);
  v("confirm_distance_m", o.confirm_distance_m);
  v("confirm_angle_rad", o.confirm_angle_rad);
  v("win_margin", o.win_margin);
  v("confirm_updates", o.confirm_updates);
  v("global_candidates", o.global_candidates);
  v("distinct_radius_m", o.distinct_radius_m);
  v("distinct_angle_rad", o.distinct_angle_rad);
  v("ambiguity_margin", o.ambiguity_margin);
  v("resume_updates", o.resume_updates);
  v("slip_radius_m", o.slip_radius_m);
  v("slip_angle_rad", o.slip_angle_rad);
  v("odometry_gap_s", o.odometry_gap_s);
  v("scan_matched_search_m", o.scan_matched_search_m);
  v("search_max_range_m", o.search_max_range_m);
  v("search_resolution_m", o.search_resolution_m);
  v("search_window_m", o.search_window_m);
  v("max_lost_s", o.max_lost_s);
  v("reset_sigma_xy_m", o.reset_sigma_xy_m);
  v("reset_sigma_yaw_rad", o.reset_sigma_yaw_rad);
}

/// Everything the particle filter can be told. Defaults are the improved filter (likelihood
/// field, x/y/yaw search, best-shift moves, Gauss-Newton refinement, rot-trans-rot noise,
/// systematic resampling, updates every 0.25 m or 0.1 rad); `ReportsPreset()` reproduces the
/// ECE276A reports.
struct ParticleFilterOptions {
  int num_particles = 100;
  std::uint64_t seed = 1;  ///< one RNG stream for prediction and resampling

  MotionNoiseModel motion_noise = MotionNoiseModel::kRotTransRot;
  double sigma_xy_m = 0.01;      ///< kGaussianPerStep: per step, x and y (world frame)
  double sigma_yaw_rad = 0.005;  ///< kGaussianPerStep: per step, yaw
  RotTransRotNoise rot_trans_rot{.alpha1 = 0.02,
                                 .alpha2 = 0.01,
                                 .alpha3 = 0.01,
                                 .alpha4 = 0.0005,
                                 .min_trans_sigma_m = 0.005,
                                 .min_rot_sigma_rad = 0.003};  ///< kRotTransRot
  /// The odometry's heading drift per metre, fitted online and taken out of the prediction.
  OdometryCalibrationOptions odometry_calibration;

  ObservationModel observation = ObservationModel::kLikelihoodField;
  /// The beams used for weighting (voxel-filtered).
  ScanPointsOptions points{.min_range_m = 0.1,
                           .max_range_m = 30.0,
                           .beam_stride = 1,
                           .voxel_size_m = 0.05,
                           .sparse_fraction = 0.5};
  /// The shift search: 9x9 cells and 9 yaws 0.0075 rad apart. With kLikelihoodField its `value`
  /// must be kRawValue.
  MapCorrelatorOptions correlation{.xy_half_width_cells = 4,
                                   .yaw_half_steps = 4,
                                   .yaw_step_rad = 0.0075,
                                   .value = CorrelationValue::kRawValue,
                                   .occupied_threshold = 0.0f};
  /// The field's sigma: likelihood_field.sigma_m to start with, then following the map's own
  /// sharpness (AdaptiveSigmaOptions; `adaptive_sigma.enabled: false` keeps it). Needs the
  /// likelihood-field observation model: with `observation: correlation` turn it off.
  LikelihoodFieldOptions likelihood_field{.sigma_m = 0.08,
                                          .z_hit = 0.9,
                                          .z_rand = 0.1,
                                          .occupied_threshold = 0.0f,
                                          .cutoff_sigmas = 3.0};
  AdaptiveSigmaOptions adaptive_sigma;
  /// log-weight += observation_scale * score (the softmax temperature; 1 in the reports).
  double observation_scale = 0.5;
  /// Move each particle to its best shift (the reports' "future work"); false: only weight it.
  bool move_to_best_shift = true;
  /// Then refine each particle to sub-cell accuracy by Gauss-Newton on the likelihood field
  /// (needs move_to_best_shift); with the likelihood-field model the weight uses the refined score.
  bool refine = true;
  ScanRefinerOptions refiner;
  /// Degeneracy: a translation direction whose information in the scan's own geometry (an
  /// eigenvalue of its point-to-line J^T J, yaw marginalised) is below this fraction of the
  /// largest keeps each particle's odometry prediction (solution remapping, Zhang et al. 2016),
  /// and the weights do not depend on it: along a corridor's axis the scan says nothing. There
  /// the estimate and the cloud's weighted mean also follow the odometry (the cloud is shifted
  /// back along the axis after resampling; each particle keeps its own spread). 0 = off. A
  /// corridor's axis seen only through a few far door frames holds 5-20 % of the strongest
  /// direction's information, and there the match pulls the estimate back to where the map was
  /// written from, update after update; 15 % holds it, where a quarter starts to cost the real
  /// logs (docs/studies/pf-corridor.md).
  double degeneracy_ratio = 0.15;
  /// Beams meeting their surface at a larger incidence angle (beam to surface normal, the normal
  /// from the neighbouring points) are left out of the weighting and the degeneracy analysis.
  /// pi / 2 (the default) keeps every point: with the degeneracy handling on, dropping grazing
  /// points also drops the near walls' constraints, which the corridor needs.
  double max_incidence_rad = 1.5707963267948966;

  /// When every particle that carries weight lies within unimodal_radius_m and unimodal_yaw_rad
  /// of the weighted mean, the mean is the estimate and the map is updated there; a spread-out or
  /// split cloud, or a scan with a degenerate direction, keeps its best particle. 0 = always the
  /// best particle: the default, because the mean helps some logs and hurts others as much
  /// (docs/studies/from-code-comments.md).
  double unimodal_radius_m = 0.0;
  double unimodal_yaw_rad = 0.1;

  RelocalisationOptions relocalisation;

  ResamplingScheme resampling = ResamplingScheme::kSystematic;
  /// Resample when Neff = 1 / sum(w^2) < resample_neff_ratio * num_particles (reports: 0.5).
  double resample_neff_ratio = 0.5;

  OccupancyGridOptions map;  ///< the map built from the best particle

  /// Filter only after the robot moved this far or turned this much since the last update
  /// (GMapping's linear/angular update); in between, poses follow the odometry and the map is
  /// left alone (inserting every scan of a 40 Hz lidar wears the walls away). 0 and 0: every
  /// scan, as in the reports.
  double min_update_distance_m = 0.25;
  double min_update_angle_rad = 0.1;

  /// Worker threads for the per-particle scoring (results do not depend on it); 0: one per
  /// processor this process may use, or SLAMRIG_THREADS (DefaultThreadCount).
  int num_threads = 0;

  /// The ECE276A reports' method: Gaussian prediction noise, all beams, 9x9 x/y shifts, no yaw
  /// shift, softmax of correlations, stratified resampling at Neff < N/2, particles not moved,
  /// per-beam map updates with +log 4 / -log 4 / clamps.
  static ParticleFilterOptions ReportsPreset();

  /// One message per broken rule, e.g. "pf.num_particles = 0; must be > 0".
  std::vector<std::string> Validate() const;
};

/// The field table of ParticleFilterOptions (slam/config/fields.h): the keys of a scenario's
/// `slam: {NAME: {algorithm: pf, ...}}` entry, of `--set slam.NAME.KEY=...` and of the messages of
/// Validate(). `seed` is not a field: it derives from the run's seed.
template <typename V>
void VisitFields(V& v, ParticleFilterOptions& o) {
  v("particles", o.num_particles);
  v.Enum("motion_noise", o.motion_noise,
         {{MotionNoiseModel::kGaussianPerStep, "gaussian"},
          {MotionNoiseModel::kRotTransRot, "rot_trans_rot"}});
  v("sigma_xy_m", o.sigma_xy_m);
  v("sigma_yaw_rad", o.sigma_yaw_rad);
  v.Struct("rot_trans_rot", o.rot_trans_rot);
  v.Struct("odometry_calibration", o.odometry_calibration);
  v.Enum("observation", o.observation,
         {{ObservationModel::kMapCorrelation, "correlation"},
          {ObservationModel::kLikelihoodField, "likelihood_field"}});
  v.Struct("points", o.points);
  v.Struct("correlation", o.correlation);
  v.Struct("likelihood_field", o.likelihood_field);
  v.Struct("adaptive_sigma", o.adaptive_sigma);
  v("observation_scale", o.observation_scale);
  v("move_to_best_shift", o.move_to_best_shift);
  v("refine", o.refine);
  v.Struct("refiner", o.refiner);
  v("degeneracy_ratio", o.degeneracy_ratio);
  v("max_incidence_rad", o.max_incidence_rad);
  v("unimodal_radius_m", o.unimodal_radius_m);
  v("unimodal_yaw_rad", o.unimodal_yaw_rad);
  v.Struct("relocalisation", o.relocalisation);
  v("min_update_distance_m", o.min_update_distance_m);
  v("min_update_angle_rad", o.min_update_angle_rad);
  v.Enum("resampling", o.resampling,
         {{ResamplingScheme::kSystematic, "systematic"},
          {ResamplingScheme::kStratified, "stratified"}});
  v("resample_neff_ratio", o.resample_neff_ratio);
  v("threads", o.num_threads);
  v.Struct("map", o.map);
}

}  // namespace slamrig::slam
