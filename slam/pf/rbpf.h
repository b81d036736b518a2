#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "slam/grid/tiled_grid.h"
#include "slam/odometry/gaussian.h"
#include "slam/pf/rbpf_matcher.h"
#include "slam/pf/rbpf_options.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"
#include "slam/types/thread_pool.h"

namespace slamrig::slam {

/// One pose of a particle's trajectory. Particles that share a past share its nodes: resampling
/// copies a pointer, not a trajectory.
struct RbpfPoseNode {
  RbpfPoseNode(const Pose2& p, std::shared_ptr<RbpfPoseNode> before)
      : pose(p), parent(std::move(before)) {}
  /// Releases the chain only this node keeps alive iteratively (a recursive release of a long
  /// chain would exhaust the stack).
  ~RbpfPoseNode();
  RbpfPoseNode(const RbpfPoseNode&) = delete;
  RbpfPoseNode& operator=(const RbpfPoseNode&) = delete;

  Pose2 pose;
  std::shared_ptr<RbpfPoseNode> parent;  ///< the pose at the previous update; null at the first
};

/// One hypothesis of the robot's path with its own map.
struct RbpfParticle {
  Pose2 pose;
  double log_weight = 0.0;  ///< since the last resampling (normalised: max 0 after each step)
  /// Sum of the log proposal normalisers along the particle's whole ancestry: ranks paths.
  double path_log_likelihood = 0.0;
  TiledGrid map;
  std::shared_ptr<RbpfPoseNode> history;  ///< the pose at every update, newest first
};

/// What one AddScan did.
struct RbpfStep {
  Pose2 best_pose;  ///< the pose of the particle with the most likely path
  Pose2 mean_pose;  ///< weighted mean (circular in yaw)
  double neff = 0.0;
  bool resampled = false;
  bool updated = false;           ///< false: the robot moved too little, poses follow the odometry
  int failed_matches = 0;         ///< particles whose scan match failed (odometry proposal)
  double matched_fraction = 0.0;  ///< of the best particle's scan points, at its new pose
  /// The odometry check replaced the increment by the best particle's wide match.
  bool odometry_rejected = false;
  /// The exponent the weights took this update (weight_exponent times the independent-point
  /// factor of weight_correlation_length_m; per point, times the points' mean factor).
  double weight_exponent = 1.0;
  /// The map check's (RbpfOptions::map_check_window_m) witness at this update, if it found one:
  /// how far the best particle is from the place its map holds for the scan (RingOffsetRms at
  /// Rbpf::kContradictionRadiusM; 0: no witness).
  double map_contradiction_m = 0.0;
};

/// How far apart two poses put the robot, heading included: the root mean square, over the points
/// of a circle of `radius_m` about the robot, of the distance between each point placed at `a` and
/// at `b`, sqrt(|t(a) - t(b)|^2 + 2 (1 - cos(a - b)) radius^2) (the cross term averages out
/// around the circle). The translation's difference alone at radius 0; a heading's adds the
/// chord it sweeps at that radius.
double RingOffsetRms(const Pose2& a, const Pose2& b, double radius_m);

/// Where the map check found the map holding a scan (RbpfOptions::map_check_window_m).
struct RbpfMapWitness {
  int update = 0;  ///< the update, counted as BestUpdatePoses() is indexed
  Pose2 place;     ///< the scan's place on the best particle's map
};

/// A Rao-Blackwellised particle filter with per-particle maps, GMapping's method (Grisetti,
/// Stachniss, Burgard, "Improved Techniques for Grid Mapping with Rao-Blackwellized Particle
/// Filters", IEEE T-RO 23(1), 2007, Table I): each particle's scan is matched against its own map
/// from the odometry prediction; K poses around the match, weighted by observation likelihood
/// times motion prior, give a Gaussian (Eqs. 15-17) from which the new pose is drawn, and their
/// sum, the normaliser eta (Eq. 18), multiplies the weight; a failed match falls back on the
/// odometry model. Resampling only when Neff < N/2 (Sec. V). The maps are TiledGrids, so that a
/// resampled particle copies a tile table. Deterministic for a seed, whatever `num_threads` is.
class Rbpf {
 public:
  explicit Rbpf(const RbpfOptions& options);

  /// Processes one scan; `odometry_increment` is the robot-frame motion since the previous scan
  /// (ignored for the first, which starts every map at the identity pose).
  /// `odometry_gap_s`: how long the odometry was silent before it (SyncedScan::odometry_gap_s).
  RbpfStep AddScan(const LaserScan& scan, const Pose2& odometry_increment,
                   double odometry_gap_s = 0.0);

  /// Tells the filter that its increments are scan matches, not the robot's own odometry
  /// (RbpfOptions::scan_matched_window_m).
  void SetScanMatchedIncrements(bool scan_matched) { scan_matched_increments_ = scan_matched; }

  const std::vector<RbpfParticle>& particles() const { return particles_; }
  /// The particle with the most likely path.
  const RbpfParticle& best() const { return particles_[best_]; }
  /// The best particle's pose at every update, oldest first.
  std::vector<Pose2> BestUpdatePoses() const;
  /// Distinct map tiles over all particles (the memory the maps hold, in tiles).
  int DistinctTiles() const;
  int resample_count() const { return resample_count_; }
  int update_count() const { return update_count_; }
  /// Updates whose odometry increment the check replaced
  /// (RbpfOptions::odometry_failure_probability).
  int odometry_rejections() const { return odometry_rejections_; }
  /// Updates whose increment the search at every heading replaced: after an odometry gap
  /// (RbpfOptions::odometry_gap_s), or an alias of a scan-matched increment
  /// (RbpfOptions::scan_matched_window_m).
  int gap_corrections() const { return gap_corrections_; }
  const RbpfOptions& options() const { return options_; }
  /// The map check's witnesses so far (RbpfOptions::map_check_window_m).
  const std::vector<RbpfMapWitness>& map_witnesses() const { return map_witnesses_; }
  /// The odometry's travel after a map witness within which the best path may come back to the
  /// place its map held (an update or two after a wrong step: the odometry check's window or a
  /// particle's later match), and the radius at which a contradiction is measured: a heading
  /// error counts by the chord it sweeps over that travel.
  static constexpr double kContradictionRadiusM = 2.0;
  /// How far the best path contradicts the best particle's map: the largest, over the map
  /// check's witnesses, of the least distance (RingOffsetRms at kContradictionRadiusM) between
  /// the final best path and the witness's place carried on by the odometry, over the updates
  /// within kContradictionRadiusM of travel from the witness's. A contradiction the path took
  /// back (a later match, or a resampling that kept a path agreeing with the witness) does not
  /// count. 0 without witnesses.
  double MapContradictionM() const;

 private:
  /// What every particle's update of one scan shares.
  struct ScanUpdate {
    Pose2 motion;  ///< the increment since the last update
    const std::vector<MatchPoint>* points;
    const LaserScan* scan;
    std::optional<double> map_range_m;  ///< the map takes returns out to this (SparseScanRange)
    double weight_exponent;
  };
  /// Moves a particle by the update's motion, draws its pose from the proposal, updates its map.
  void UpdateParticle(RbpfParticle& particle, const ScanUpdate& update, std::uint64_t seed,
                      bool* failed) const;

  void Resample(const std::vector<double>& weights);
  /// The increment the particles move by: `pending` (the odometry since the last update), or
  /// after a gap the search's (SearchAfterGap), or the odometry check's (CheckOdometry), then
  /// with scan-matched increments the alias search's; counts what it replaced, and sets
  /// `*rejected` when the odometry check or the alias search did.
  /// `*near_climb`: the best particle's climb from the returned increment's prediction where one
  /// of them made it (the odometry check's, when the increment is the one it kept), else empty.
  Pose2 ChooseMotion(const Pose2& pending, bool after_gap, const std::vector<MatchPoint>& points,
                     bool* rejected, std::optional<ClimbResult>* near_climb);
  /// The odometry check: `motion`, or the increment the best particle's wide match gives where
  /// the mixture model finds that more likely (then `*rejected` is set). `near`, when given,
  /// receives the best particle's climb from the prediction with the motion prior.
  Pose2 CheckOdometry(const Pose2& motion, const std::vector<MatchPoint>& points, bool* rejected,
                      ClimbResult* near = nullptr) const;
  /// The place within +-`half_m` of `center` and +-`yaw_half_rad` of its heading (pi: every
  /// heading) where `points` fit `map` by the alias search's rules (scan_matched_window_m): a
  /// matched fraction of at least scan_matched_accept_ratio of the long-term level, above
  /// `near_fraction` by scan_matched_win_margin of it, and no other heading within the odds of a
  /// failed increment.
  std::optional<Pose2> PlaceInMap(const TiledGrid& map, const std::vector<MatchPoint>& points,
                                  const Pose2& center, double half_m, double yaw_half_rad,
                                  double near_fraction) const;
  /// The best particle's climb from `motion`'s prediction with the motion prior: `climbed` where
  /// the caller has it, else climbed here.
  ClimbResult NearClimb(const Pose2& motion, const std::vector<MatchPoint>& points,
                        const std::optional<ClimbResult>& climbed) const;
  /// Where the increments are scan matches (RbpfOptions::scan_matched_window_m): the increment
  /// to the best place within the window at every heading on the best particle's map, where the
  /// match near the prediction falls short of the long-term matched fraction and the place found,
  /// unique among the headings, does not (`*moved`); `motion` itself otherwise. `climbed`: the
  /// climb from `motion`'s prediction where the caller has it (CheckOdometry's, when it kept
  /// the increment), else climbed here.
  Pose2 SearchScanMatchedAlias(const Pose2& motion, const std::vector<MatchPoint>& points,
                               const std::optional<ClimbResult>& climbed, bool* moved) const;
  /// The map check (RbpfOptions::map_check_window_m), in two halves around the particles'
  /// update. Start: where the best particle's match near `motion`'s prediction falls below half
  /// the long-term matched fraction and most of its points that find no wall land on cells the
  /// map has seen free (not new ground), that particle's map as it was before the scan.
  struct MapCheck {
    TiledGrid map;  ///< shares its tiles with the particle's map at the start
    Pose2 predicted;
    double near_fraction;
  };
  /// `climbed`: as for NearClimb.
  std::optional<MapCheck> StartMapCheck(const Pose2& motion, const std::vector<MatchPoint>& points,
                                        const std::optional<ClimbResult>& climbed) const;
  /// Finish: where the pose the filter chose (`chosen`) fits that map poorly too, the place the
  /// map holds for the scan, searched within a quarter turn of the prediction by the alias
  /// search's rules (PlaceInMap): the witness.
  std::optional<Pose2> FinishMapCheck(const MapCheck& check, const std::vector<MatchPoint>& points,
                                      const Pose2& chosen) const;
  /// The share of `points` at `pose` that the matcher counts as matched on `map`.
  double MatchedFraction(const TiledGrid& map, const std::vector<MatchPoint>& points,
                         const Pose2& pose) const;
  /// After an odometry gap: the most likely of the match near the prediction and the best match
  /// within +-odometry_gap_window_m at every heading, as an increment (`*moved` when it is the
  /// latter).
  Pose2 SearchAfterGap(const Pose2& motion, const std::vector<MatchPoint>& points,
                       bool* moved) const;
  /// The best match on `map` at any heading within +-`half_m` of `center` (a grid, then climbs
  /// with `prior` from its best distinct headings), its log-likelihood, and (when `runner_up` is
  /// given) the best log-likelihood of a climb that ended at another heading. The grid's steps are
  /// `coarsening` times odometry_window_step_m and 0.02 rad.
  Pose2 BestAtAnyHeading(const TiledGrid& map, const std::vector<MatchPoint>& points,
                         const Pose2& center, double half_m, double yaw_half_rad,
                         const PosePrior& prior, double* log_likelihood, double* runner_up,
                         int coarsening = 1) const;
  /// `far` with its translation from `near` dropped along the directions in which the scan
  /// cannot place the robot (odometry_degenerate_ratio).
  Pose2 RemapDegenerate(const TiledGrid& map, const std::vector<MatchPoint>& points,
                        const Pose2& near, const Pose2& far) const;
  /// weight_exponent times min(1, independent points / points) (weight_correlation_length_m);
  /// weight_exponent alone where the points carry the tempering (weight_correlation_per_point).
  double WeightExponent(const std::vector<MatchPoint>& points) const;
  /// The motion model's standard deviations (x, y each; yaw) for an increment.
  std::pair<double, double> MotionSigmas(const Pose2& motion) const;

  RbpfOptions options_;
  RbpfMatcher matcher_;
  RandomEngine rng_;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<RbpfParticle> particles_;
  std::size_t best_ = 0;
  bool started_ = false;
  bool scan_matched_increments_ = false;  // SetScanMatchedIncrements
  Pose2 pending_motion_;
  RbpfStep last_step_;
  int resample_count_ = 0;
  int update_count_ = 0;
  int odometry_rejections_ = 0;
  int gap_corrections_ = 0;
  // The best particle's matched fraction, averaged slowly over the updates (its long-term level;
  // an update below half of it leaves it alone), and the updates averaged.
  double matched_level_ = 0.0;
  int matched_samples_ = 0;
  double pending_gap_s_ = 0.0;  // the longest odometry gap since the last update
  std::vector<RbpfMapWitness> map_witnesses_;
  std::vector<Pose2> update_odometry_;  // the odometry from each update to the next
};

}  // namespace slamrig::slam
