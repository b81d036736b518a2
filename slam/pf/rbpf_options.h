#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/scan_points.h"
#include "slam/pf/rbpf_matcher.h"
#include "slam/pf/resampling.h"

namespace slamrig::slam {

/// Standard deviations of the odometry motion model, per unit of the increment (GMapping's
/// srr, srt, str, stt): in the robot frame, sigma_xy = xy_per_m |trans| + xy_per_rad |rot| +
/// min_xy_m, sigma_yaw = yaw_per_m |trans| + yaw_per_rad |rot| + min_yaw_rad.
struct RbpfMotionNoise {
  double xy_per_m = 0.1;       ///< m of position spread per m travelled
  double xy_per_rad = 0.2;     ///< m of position spread per rad turned
  double yaw_per_m = 0.1;      ///< rad of heading spread per m travelled
  double yaw_per_rad = 0.2;    ///< rad of heading spread per rad turned
  double min_xy_m = 0.01;      ///< floor on sigma_xy
  double min_yaw_rad = 0.005;  ///< floor on sigma_yaw

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of RbpfMotionNoise (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, RbpfMotionNoise& o) {
  v("xy_per_m", o.xy_per_m);
  v("xy_per_rad", o.xy_per_rad);
  v("yaw_per_m", o.yaw_per_m);
  v("yaw_per_rad", o.yaw_per_rad);
  v("min_xy_m", o.min_xy_m);
  v("min_yaw_rad", o.min_yaw_rad);
}

/// Everything the Rao-Blackwellised particle filter (slam/pf/rbpf.h) can be told.
struct RbpfOptions {
  int num_particles = 30;
  std::uint64_t seed = 1;  ///< seeds one stream per particle and step, and the resampling

  /// The beams used for matching (voxel-filtered).
  ScanPointsOptions points{.min_range_m = 0.1,
                           .max_range_m = 30.0,
                           .beam_stride = 1,
                           .voxel_size_m = 0.05,
                           .sparse_fraction = 0.5};
  RbpfMatcherOptions matcher;
  RbpfMotionNoise motion;
  /// The proposal's sample points: a 3 x 3 x 3 grid of these steps around the match (GMapping's
  /// llsamplestep, lasamplestep), weighted by likelihood times motion prior.
  double proposal_xy_step_m = 0.01;
  double proposal_yaw_step_rad = 0.005;
  /// The new pose is the proposal's mean plus proposal_spread times a draw of its covariance:
  /// 1 samples the Gaussian (the paper's Eq. 17), 0 takes its mean (the openslam gmapping code
  /// keeps the matched pose). Every draw is inserted into the particle's map, so the spread is
  /// noise the map keeps.
  double proposal_spread = 1.0;
  /// p(z | m, x) = exp(observation_scale * log-likelihood): below 1 the beams count as
  /// correlated (GMapping flattens its weights in the same way).
  double observation_scale = 0.2;
  /// The importance weight is multiplied by eta ^ weight_exponent, not by eta: a tempered weight
  /// (GMapping flattens its weights in the same way, obsSigmaGain), on top of the independent-point
  /// factor below. The proposal and the odometry check keep the full observation_scale (a
  /// tempered check misses reversals the odometry reports as forward motion). 1 = no further
  /// tempering (the default: a uniform exponent flattens the sparse scans of open halls as much
  /// as the dense ones of corridors).
  double weight_exponent = 1.0;
  /// Tempering from the scan's independent points: end points closer than this to each other
  /// count as one piece of evidence (CountIndependentPoints), and the weight takes eta ^ (e *
  /// weight_exponent) with e = min(1, N_independent / N_points). The per-beam likelihood treats
  /// the beams as independent; they are not where their end points lie within the likelihood
  /// field's reach of each other, since neighbouring beams then read the same few map cells and
  /// share their errors (Thrun, Burgard, Fox, Probabilistic Robotics, Sec. 6.4 and 6.8: beam
  /// dependence, met by subsampling or damping). So a dense scan (many beams on a few walls) is
  /// flattened to the number of points it holds at this spacing, a sparse one (15 end points in
  /// an open hall) is left untempered. 0 = off. Default 0.1 m (twice likelihood_sigma_m), the
  /// setting docs/studies/from-code-comments.md compares.
  double weight_correlation_length_m = 0.1;
  /// How weight_correlation_length_m tempers: false, one factor for the whole scan (above); true,
  /// per point (AssignIndependenceWeights): each point's log-likelihood in the weight counts 1 /
  /// (the end points within the length of it), so a cluster on a near wall counts as one piece of
  /// evidence and an isolated far point fully, where the scan's factor discounts both alike. The
  /// weight's eta is then the proposal grid's mean of the tempered likelihood times the motion
  /// prior; the proposal, the odometry check and the best path keep the untempered likelihood.
  /// Not the default: it diverges on logs whose odometry reverses (docs/studies/
  /// from-code-comments.md).
  bool weight_correlation_per_point = false;

  /// The odometry check: the odometry model is a mixture, with this probability of a failed
  /// increment (wheel slip, a reversal reported as forward motion, a collision) whose translation
  /// is anywhere in a square window around the prediction. Each update the best particle's scan
  /// is matched over that window; where the match there, weighed by this mixture, is more likely
  /// than the one near the prediction, the increment becomes the matched one for every particle.
  /// 0 = off (the odometry is always trusted as a Gaussian).
  double odometry_failure_probability = 0.01;
  /// Half-width of the window: odometry_window_per_m per m of odometry translation (2: a
  /// reversal reported as forward motion is inside) plus odometry_window_min_m.
  double odometry_window_per_m = 2.0;
  double odometry_window_min_m = 0.1;
  double odometry_window_step_m = 0.1;  ///< spacing of the window's grid of starting poses
  /// A gap in the log: the odometry silent for longer than odometry_gap_s before an update
  /// (SyncedScan::odometry_gap_s), through which the robot may have turned while the increment
  /// held still. The check then says nothing of the increment: it matches over a window of
  /// +-odometry_gap_window_m at every heading, and the most likely match, there or near the
  /// prediction, is the increment for every particle. 0: never.
  double odometry_gap_s = 1.0;
  double odometry_gap_window_m = 1.0;
  /// Where the increments are scan matches (a source without odometry: ScanMatchedOdometry,
  /// Rbpf::SetScanMatchedIncrements), a failed increment is an alias of the prior's local map
  /// anywhere within its own search window (up to 2 m) at any heading. The best particle's map
  /// holds the whole past, where the scan fits only the true place: an update whose match near
  /// the prediction matches less than scan_matched_accept_ratio of the long-term matched
  /// fraction searches that map within this half-width at every heading, and the place found
  /// becomes the increment for every particle when it matches at least that share, beats the
  /// near match by scan_matched_win_margin of the long-term level, and no other heading matches
  /// within the odds of a failed increment (odometry_failure_probability; 0: never searched) (the
  /// pf's relocalisation.scan_matched_search_m). 0: never.
  double scan_matched_window_m = 2.0;
  double scan_matched_accept_ratio = 0.8;
  double scan_matched_win_margin = 0.1;
  /// A direction in which the scan's information at the window's match is below this fraction of
  /// its information in the best-determined direction is degenerate (a corridor's axis): the
  /// match's displacement along it is dropped and the odometry kept there (Zhang, Kaess, Singh,
  /// ICRA 2016, solution remapping). 0 = every direction trusted.
  double odometry_degenerate_ratio = 0.45;
  /// The check weighs a failed turn too: with odometry_failure_probability the wheels' heading
  /// is anywhere within a quarter turn of the prediction (a turn on the spot the encoders missed)
  /// while the position stays the Gaussian's. The best match at such a heading replaces the
  /// increment where it is more likely than the others, the Gaussian does not explain it better,
  /// and the scan picks it out (no other heading matches within the same odds: not a corridor
  /// seen from either end). Off by default: on the ten logs with twice their odometry noise it
  /// takes the rbpf on seattle from 13.1 to 0.91 m and freiburg-079 from 4.67 to 0.16 m, on the
  /// clean logs it costs edmonton (0.45 to 1.29 m) and intel (0.094 to 0.146 m) more than it
  /// gives belgioioso (0.33 to 0.25 m) (docs/studies/rbpf-turns.md).
  bool odometry_turn_check = false;
  /// The map check, which judges and moves nothing: on an update whose best particle matches
  /// near the prediction less than half the long-term matched fraction, on ground its map has
  /// seen free, and whose chosen pose fits that map (as it was before the scan) poorly too, the
  /// map is searched within this half-width and a quarter turn of the prediction. A place found
  /// there by the alias search's rules (scan_matched_accept_ratio, scan_matched_win_margin,
  /// unique among headings within the odds of odometry_failure_probability) is where the map
  /// holds the scan: a witness. Where the best path, at the end, put the scan far from its
  /// witness, the map contradicts the path (Rbpf::MapContradictionM). 0: never searched.
  double map_check_window_m = 2.0;

  ResamplingScheme resampling = ResamplingScheme::kSystematic;
  /// Resample when Neff < resample_neff_ratio * num_particles (selective resampling).
  double resample_neff_ratio = 0.5;

  OccupancyGridOptions map;  ///< every particle's map
  /// Every particle's map records where in each cell its hits fell (TiledGrid::HitMean, GMapping's
  /// PointAccumulator), and the matcher measures a point's distance to that mean, not to the
  /// cell's centre: a wall seen at a sub-cell offset is matched there, not on the 5 cm lattice.
  /// Costs three floats per cell.
  bool cell_hit_means = true;

  /// Filter only after the robot moved this far or turned this much since the last update; in
  /// between, poses follow the odometry and the maps are left alone.
  double min_update_distance_m = 0.25;
  double min_update_angle_rad = 0.1;

  /// Worker threads for the per-particle work (results do not depend on it); 0: one per
  /// processor this process may use, or SLAMRIG_THREADS (DefaultThreadCount).
  int num_threads = 0;

  /// One message per broken rule, e.g. "particles = 0; must be > 0".
  std::vector<std::string> Validate() const;
};

/// The field table of RbpfOptions: the keys of `slam: {NAME: {algorithm: rbpf, ...}}` and of
/// `--set`. `seed` is not a field: it derives from the run's seed.
template <typename V>
void VisitFields(V& v, RbpfOptions& o) {
  v("particles", o.num_particles);
  v.Struct("points", o.points);
  v.Struct("matcher", o.matcher);
  v.Struct("motion", o.motion);
  v("proposal_xy_step_m", o.proposal_xy_step_m);
  v("proposal_yaw_step_rad", o.proposal_yaw_step_rad);
  v("proposal_spread", o.proposal_spread);
  v("observation_scale", o.observation_scale);
  v("weight_exponent", o.weight_exponent);
  v("weight_correlation_length_m", o.weight_correlation_length_m);
  v("weight_correlation_per_point", o.weight_correlation_per_point);
  v("odometry_failure_probability", o.odometry_failure_probability);
  v("odometry_window_per_m", o.odometry_window_per_m);
  v("odometry_window_min_m", o.odometry_window_min_m);
  v("odometry_window_step_m", o.odometry_window_step_m);
  v("odometry_gap_s", o.odometry_gap_s);
  v("odometry_gap_window_m", o.odometry_gap_window_m);
  v("scan_matched_window_m", o.scan_matched_window_m);
  v("scan_matched_accept_ratio", o.scan_matched_accept_ratio);
  v("scan_matched_win_margin", o.scan_matched_win_margin);
  v("odometry_degenerate_ratio", o.odometry_degenerate_ratio);
  v("odometry_turn_check", o.odometry_turn_check);
  v("map_check_window_m", o.map_check_window_m);
  v.Enum("resampling", o.resampling,
         {{ResamplingScheme::kSystematic, "systematic"},
          {ResamplingScheme::kStratified, "stratified"}});
  v("resample_neff_ratio", o.resample_neff_ratio);
  v.Struct("map", o.map);
  v("cell_hit_means", o.cell_hit_means);
  v("min_update_distance_m", o.min_update_distance_m);
  v("min_update_angle_rad", o.min_update_angle_rad);
  v("threads", o.num_threads);
}

}  // namespace slamrig::slam
