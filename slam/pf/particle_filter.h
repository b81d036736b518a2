#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/correlative_matcher.h"
#include "slam/matching/likelihood_field.h"
#include "slam/matching/map_correlator.h"
#include "slam/matching/scan_refiner.h"
#include "slam/matching/solution_remapping.h"
#include "slam/odometry/odometry_calibration.h"
#include "slam/pf/particle_filter_options.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"
#include "slam/types/thread_pool.h"

namespace slamrig::slam {

/// One pose hypothesis and its normalised weight.
struct Particle {
  Pose2 pose;
  double weight = 0.0;
};

/// What one AddScan did.
struct ParticleFilterStep {
  /// The estimate, where the map was updated: the weighted mean when the cloud is one tight mode
  /// (ParticleFilterOptions::unimodal_radius_m), else the highest-weight particle.
  Pose2 best_pose;
  Pose2 mean_pose;    ///< weighted mean (circular mean for yaw)
  double neff = 0.0;  ///< effective sample size after the update, before resampling
  bool resampled = false;
  bool updated = false;     ///< false: the robot moved too little, poses follow the odometry
  float best_score = 0.0f;  ///< observation score of the best particle
  int points_used = 0;      ///< scan points used for weighting
  /// The best particle's match quality: its score / (points x the field's maximum), in [0, 1].
  double quality = 0.0;
  bool lost = false;         ///< the filter is lost: the map is frozen, the cloud goes on filtering
  bool relocalised = false;  ///< a global match was confirmed and the cloud put there
  /// The odometry was silent before this update (RelocalisationOptions::odometry_gap_s) and the
  /// search at every heading near by moved the cloud.
  bool gap_corrected = false;
};

/// Particle-filter SLAM on one shared log-odds map, as in the UCSD ECE276A reports (Wang,
/// "Simultaneous Localization and Mapping with Texture", Sec. II-III; Zafari, "Particle Filter
/// SLAM", algorithm steps 1-7): predict every particle with the odometry increment plus noise,
/// score its scan against the map over a shift grid (map correlation or likelihood field), update
/// the weights by softmax, update the map from the best particle, and resample when Neff drops.
/// Deterministic for a seed, whatever `num_threads` is.
class ParticleFilter {
 public:
  explicit ParticleFilter(const ParticleFilterOptions& options);

  /// Processes one scan. `odometry_increment` is the robot-frame motion since the previous scan
  /// (ignored for the first scan, which only starts the map at the identity pose);
  /// `odometry_gap_s` how long the odometry was silent before it (SyncedScan::odometry_gap_s).
  ParticleFilterStep AddScan(const LaserScan& scan, const Pose2& odometry_increment,
                             double odometry_gap_s = 0.0);

  /// Tells the filter that its increments are scan matches, not the robot's own odometry
  /// (RelocalisationOptions::scan_matched_search_m).
  void SetScanMatchedIncrements(bool scan_matched) { scan_matched_increments_ = scan_matched; }

  const std::vector<Particle>& particles() const { return particles_; }
  const OccupancyGrid& map() const { return map_; }
  const ParticleFilterOptions& options() const { return options_; }
  /// Number of resampling events so far.
  int resample_count() const { return resample_count_; }
  /// Times the filter found itself lost, and was relocalised by a global match.
  int lost_count() const { return lost_count_; }
  int relocalisation_count() const { return relocalisation_count_; }
  /// Lost alarms that ended with the tracked hypothesis matching well again (no relocalisation).
  int resumed_count() const { return resumed_count_; }
  /// Updates after an odometry gap on which the search at every heading moved the cloud.
  int gap_correction_count() const { return gap_correction_count_; }
  /// The likelihood field's sigma now, and the smoothed median wall distance it follows
  /// (AdaptiveSigmaOptions).
  double field_sigma_m() const { return likelihood_field_.sigma_m(); }
  double wall_distance_m() const { return field_sigma_.median_m(); }
  /// The odometry's heading drift fitted so far (OdometryCalibrationOptions), rad per metre.
  double odometry_drift_rad_per_m() const { return calibration_.drift_rad_per_m(); }

 private:
  // A place elsewhere on the map, carried by the odometry from update to update.
  struct Candidate {
    Pose2 pose;
    double quality = 0.0;  // on the latest update
    int wins = 0;          // lost updates in a row on which it won clearly
  };
  // What one lost update decides.
  enum class LostDecision {
    kResume,       // tracking resumes where the filter is
    kCorrectSlip,  // tracking resumes at the better place near by (the odometry slipped)
    kStayLost,     // still lost: the search goes on (or gives up after max_lost_s)
    kRelocalise,   // a place elsewhere won clearly, confirm_updates times: the cloud moves there
  };
  struct LostVerdict {
    LostDecision decision = LostDecision::kStayLost;
    Pose2 pose;  // the place near by (kCorrectSlip) or elsewhere (kRelocalise)
  };

  // AddScan's steps. The first scan starts the map at the identity.
  ParticleFilterStep Start(const LaserScan& scan);
  // The odometry since the last update reaches min_update_distance_m or min_update_angle_rad.
  bool MovedEnough() const;
  // The last update's step carried on by the odometry since (no filtering).
  ParticleFilterStep FollowOdometry() const;
  // Scores the particles' scans into their log-weights and normalises them; sets the step's
  // best_pose (the highest weight) and best_score. The normalised weights.
  std::vector<double> UpdateWeights(const std::vector<Eigen::Vector2d>& points,
                                    const MatchConstraints& constraints,
                                    const Pose2& predicted_mean, ParticleFilterStep* step);
  // The step's mean_pose and the estimate (best_pose): the mean of one tight mode, held at the
  // odometry's prediction along the scan's weak directions.
  void ChooseEstimate(const MatchConstraints& constraints, bool degenerate,
                      const Pose2& predicted_mean, ParticleFilterStep* step) const;
  // Inserts the scan into the map unless it is suspect or the filter is lost (then it relocalises
  // or resumes), and follows the lost test. False when the update ends here: the filter has just
  // been found lost, or has been relocalised.
  bool UpdateMapAndLostState(const LaserScan& scan, const std::vector<Eigen::Vector2d>& points,
                             ParticleFilterStep* step);
  // Draws a new cloud of equal weights from `weights` (ParticleFilterOptions::resampling).
  void ResampleCloud(const std::vector<double>& weights);

  void Predict(const Pose2& odometry_increment);
  double Quality(float score, std::size_t num_points) const;
  // Every particle that carries weight lies within unimodal_radius_m / unimodal_yaw_rad of `mean`.
  bool Unimodal(const Pose2& mean) const;
  /// Shifts the cloud so that its weighted mean along the scan's weak directions is
  /// `predicted_mean`'s (solution remapping applied to the cloud as a whole).
  void HoldMeanAlongWeakDirections(const Pose2& predicted_mean,
                                   const MatchConstraints& constraints);
  // Updates the quality averages; true when this scan is suspect (not to be inserted).
  bool TrackQuality(double quality, Time now);
  // A pose matched on the likelihood field and its quality (Quality()).
  struct ScoredPose {
    Pose2 pose;
    double quality = 0.0;
  };
  // Forgets the places followed while lost.
  void ClearCandidates();
  // Forgets the places and the search grids of the lost state.
  void ForgetSearch();
  // One update while lost: follow the candidate places, gather the map's best places, decide.
  // False when tracking resumes and the scan is to be filtered as usual.
  bool Relocalise(const std::vector<Eigen::Vector2d>& points, const LaserScan& scan,
                  ParticleFilterStep* step);
  // The candidates that still explain this scan where the odometry carried them, merged.
  std::vector<Candidate> FollowCandidates(const std::vector<Eigen::Vector2d>& points);
  // Adds the map's best distinct places for this scan (a global search) to `places`.
  void GatherGlobalPlaces(const std::vector<Eigen::Vector2d>& points,
                          std::vector<Candidate>* places);
  // Judges `places` against the tracked hypothesis and the best place near it; keeps the
  // candidates for the next lost update.
  LostVerdict Decide(const std::vector<Eigen::Vector2d>& points, const ScoredPose& tracked,
                     std::vector<Candidate> places);
  // After an odometry gap (RelocalisationOptions::odometry_gap_s), or at every update where the
  // increments are scan matches: the best place within `radius_m` of the estimate at every
  // heading; when it fits as a place and beats the filter's own match by win_margin, the cloud
  // moves there. True when it moved.
  bool SearchNear(const std::vector<Eigen::Vector2d>& points, double radius_m,
                  ParticleFilterStep* step);
  // Moves the whole cloud, and the step's estimate and mean, by the rigid correction that puts
  // the estimate at `to` (a slip corrected, a turn found after a gap).
  void MoveCloud(const Pose2& to, ParticleFilterStep* step);
  // A new cloud around `place` (reset_sigma_*), tracking from there.
  void RestartAt(const Pose2& place, ParticleFilterStep* step);
  // Farther apart than distinct_radius_m or distinct_angle_rad.
  bool DistinctPlaces(const Pose2& a, const Pose2& b) const;
  void ResumeTracking();
  // The fraction of `points` seen from `pose` that land on observed map cells.
  double ObservedFraction(const std::vector<Eigen::Vector2d>& points, const Pose2& pose) const;
  void GiveUpWhenLostTooLong(const LaserScan& scan, ParticleFilterStep* step);
  // The shift search and refinement around `pose` on the (frozen) map.
  ScoredPose LocalMatch(const std::vector<Eigen::Vector2d>& points, const Pose2& pose);
  // The best pose within slip_radius_m and slip_angle_rad of `pose`, when it fits as a place
  // must (accept_ratio).
  std::optional<ScoredPose> NearMatch(const std::vector<Eigen::Vector2d>& points,
                                      const Pose2& pose);
  // Up to global_candidates distinct places on the whole map (searched at search_resolution_m),
  // each matched by LocalMatch and kept when it fits as a place (FitsAsPlace).
  std::vector<ScoredPose> GlobalMatches(const std::vector<Eigen::Vector2d>& near,
                                        const std::vector<Eigen::Vector2d>& points);
  // `pose` refined on the likelihood field with all `points`, when it fits as a place
  // (FitsAsPlace): the near search's judgement.
  std::optional<ScoredPose> AcceptedPlace(const std::vector<Eigen::Vector2d>& points,
                                          const Pose2& pose);
  // A match of this quality fits as a place: accept_ratio x the long-term quality from before the
  // loss, the one bar for followed, tracked, near and global places alike.
  bool FitsAsPlace(double quality) const;
  std::vector<double> Score(const std::vector<Eigen::Vector2d>& points,
                            const MatchConstraints& constraints, const Pose2& predicted_mean,
                            float* best_score);
  // Where a scan of `points` can land from a pose in `poses`, with the shift search and the
  // field's cutoff: the part of the map the field must cover for it.
  Eigen::AlignedBox2d ScanRegion(const Eigen::AlignedBox2d& poses,
                                 const std::vector<Eigen::Vector2d>& points) const;
  // ScanRegion from one pose's position.
  Eigen::AlignedBox2d ScanRegion(const Eigen::Vector2d& position,
                                 const std::vector<Eigen::Vector2d>& points) const;
  // The map's log-odds over `region` (clipped to the map) as a raster of its own, valid until the
  // next call: the map is tiles, the correlator reads rasters.
  GridView MapWindow(const Eigen::AlignedBox2d& region);

  ParticleFilterOptions options_;
  OccupancyGrid map_;
  MapCorrelator correlator_;
  LikelihoodField likelihood_field_;
  AdaptiveFieldSigma field_sigma_;
  OccupiedMask occupied_mask_;     // the map's walls for the occupied-indicator correlation
  std::vector<float> map_window_;  // MapWindow's raster
  ScanRefiner refiner_;
  RandomEngine rng_;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<Particle> particles_;
  std::vector<double> log_weights_;
  bool started_ = false;
  bool scan_matched_increments_ = false;  // SetScanMatchedIncrements
  Pose2 pending_motion_;                  // odometry since the last update
  double pending_gap_s_ = 0.0;            // the longest odometry gap since the last update
  OdometryCalibration calibration_;
  ParticleFilterStep last_step_;
  int resample_count_ = 0;
  // Lost-filter detection (augmented MCL's averages) and relocalisation.
  int tracked_updates_ = 0;
  double quality_fast_ = 0.0;
  double quality_slow_ = 0.0;
  bool lost_ = false;
  Time lost_since_;
  Pose2 lost_pose_;  // the best pose at the last update before the loss
  Eigen::Vector2d search_centre_ = Eigen::Vector2d::Zero();
  std::vector<Candidate> candidates_;  // distinct places, followed while lost
  int unsupported_updates_ = 0;        // lost updates in a row with no place elsewhere winning
  std::unique_ptr<CorrelativeMatcher> global_matcher_;
  std::unique_ptr<CorrelativeMatcher> near_matcher_;       // within slip_radius_m of the filter
  Eigen::Vector2d near_centre_ = Eigen::Vector2d::Zero();  // near_matcher_'s map: a square
  double near_half_side_m_ = 0.0;                          // around near_centre_
  int lost_count_ = 0;
  int relocalisation_count_ = 0;
  int resumed_count_ = 0;
  int gap_correction_count_ = 0;
};

/// Weighted mean of particle poses: arithmetic in x, y; circular in yaw.
Pose2 WeightedMeanPose(const std::vector<Particle>& particles);

}  // namespace slamrig::slam
