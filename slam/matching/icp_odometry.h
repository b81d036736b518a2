#pragma once

#include <Eigen/Core>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/matching/correlative_matcher.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/map_frame_drift.h"
#include "slam/matching/point_raster.h"
#include "slam/matching/scan_points.h"
#include "slam/odometry/odometry_calibration.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// The correlative search IcpOdometry runs before ICP when the prior may be outside ICP's basin.
struct IcpOdometrySearchOptions {
  /// The window: +-sigmas standard deviations of the prior (the increment's noise model scaled by
  /// the noise measured online); 0: never search.
  double sigmas = 3.0;
  /// The search runs when the window is wider than this in x and y or ...
  double trigger_window_m = 0.15;
  double trigger_window_rad = 0.1;  ///< ... in yaw, or when ICP's match from the prior failed
  double max_window_m = 2.0;        ///< the window is at most this wide ...
  double max_window_rad = 1.0;      ///< ... and this in yaw
  /// When ICP from the prior fails, or moves the prior farther than the window (by more than a
  /// raster cell or a yaw step), the prior is doubted and the window is at least this wide in x
  /// and y ... (0: the noise model's: a doubted prior is a heading's, and a wider translation
  /// window finds a long corridor's aliases; docs/studies/front-end-search.md)
  double wide_window_m = 0.0;
  /// ... and this in yaw: an odometry that under-reports a turn puts the truth outside a window
  /// drawn around the reported one. 0: the noise model's.
  double wide_window_rad = 1.0;
  double resolution_m = 0.1;  ///< the local map's raster for the search ...
  double blur_m = 0.1;        ///< ... each point blurred by a Gaussian of this sigma
  /// The searched match replaces the one from the prior when its posterior is higher by this
  /// much: the points' fit to the raster (mean raster value) less prior_weight times the squared
  /// Mahalanobis distance from the prior (sigma = window / sigmas); the prior's match wins ties.
  double min_gain = 0.02;
  double prior_weight = 0.01;
  /// The online noise measurement: an exponentially weighted mean (this weight per matched scan)
  /// of the squared corrections of clear matches, in units of the noise model's sigma; 0: off.
  double adapt_rate = 0.05;
  /// After the odometry was silent for longer than this (SyncedScan::odometry_gap_s: a gap in the
  /// log, through which the robot may have turned while the increment held still) the search
  /// runs over max_window_m and every heading, whatever the noise model says, and the update
  /// teaches neither the noise measurement nor the calibration. 0: never.
  double gap_s = 1.0;
  /// After a failed match the odometry places the scan, and the next scan's prior carries that
  /// step's error as well as its own. Up to this many failed scans in a row stay out of the local
  /// map (held), and each next scan's window covers the whole blind stretch since the last match
  /// (the noise model over its summed distance and turns), so that the stretch's error can be
  /// found against the map the last match placed. The scan that ends the stretch is matched both
  /// ways, against that map over the stretch's window and against the map with the held scans
  /// where the wheels placed them over its own window (what 0 does); the better score wins, the
  /// prior where the scores are within min_gain. A wheel error in the blind step is taken back by
  /// the first, a view the held map does not hold is matched by the second. A stretch whose window
  /// would pass max_window_m, or longer than this, ends with the wheels' placement kept: the held
  /// scans join the map (docs/studies/front-end-search.md).
  int blind_scans = 1;

  /// One message per broken rule (unprefixed; IcpOdometryOptions nests them under "search").
  std::vector<std::string> Validate() const;
};

/// Parameters of scan-to-local-map ICP odometry.
struct IcpOdometryOptions {
  /// Point-to-line ICP with a wider gate than IcpOptions' own, for logs whose scans are far apart
  /// (intel: up to ~0.5 m), light trimming and a Cauchy weight.
  IcpOptions icp = {
      .max_correspondence_distance_m = 1.0, .trim_fraction = 0.95, .kernel = RobustKernel::kCauchy};
  ScanPointsOptions points = {.voxel_size_m = 0.05, .sparse_fraction = 0.5};  ///< scan to points
  int local_map_keyframes = 10;      ///< the local map holds the points of the last N keyframes ...
  double local_map_voxel_m = 0.05;   ///< ... thinned to one point (the newest) per voxel
  double keyframe_distance_m = 0.3;  ///< a scan becomes a keyframe after moving this far ...
  double keyframe_angle_rad = 0.2;   ///< ... or turning this much since the last keyframe
  /// A match is degenerate along a direction whose standard deviation exceeds this (translation,
  /// from the match covariance's eigenvalues) ...
  double max_translation_stddev_m = 0.05;
  /// ... or whose variance exceeds this many times the other direction's (a corridor: the Hessian
  /// is nearly singular, but range noise scatters the normals enough to keep the variance itself
  /// small; a corridor's ratio is in the thousands, a room's below 20) ...
  double max_covariance_ratio = 100.0;
  double max_yaw_stddev_rad = 0.02;  ///< ... or in yaw when its standard deviation exceeds this
  /// A match also keeps the odometry along a direction the scan's own geometry hardly sees
  /// (ScanGeometry: the information of its surface normals along it below this share of the
  /// strongest direction's, as the pf's degeneracy_ratio) when it moved the pose along it farther
  /// from the odometry than weak_direction_gate_sigmas of the odometry's own noise (the
  /// increment's model times the noise measured so far): a slide, not a measurement. ICP's
  /// covariance does not see it: a far wall or a few door frames keep its Hessian's ratio below
  /// max_covariance_ratio while a short local map's overlap pulls the match back (edmonton's
  /// third scan: 0.43 m short, the wheels right to 5 cm). Within the gate the match stands.
  /// 0: off, the default: on the real logs it takes back such slides, on generated worlds it
  /// overrules as many right corrections of the wheels (docs/studies/graph.md).
  double weak_direction_ratio = 0.0;
  double weak_direction_gate_sigmas = 5.0;
  double min_score = 0.5;  ///< a match with a smaller inlier share fails
  /// A match that moves the pose farther than this from the odometry prior fails.
  double max_correction_m = 0.5;
  double max_correction_rad = 0.3;
  /// The odometry increment's noise model, for the covariance when the prior is used and the
  /// search window before the noise is measured: standard deviations of
  /// sigma_xy_per_m * distance + sigma_xy_floor_m and
  /// sigma_yaw_per_rad * |turn| + sigma_yaw_per_m * distance + sigma_yaw_floor_rad. Wheel odometry
  /// is far worse on turns than straight (the wheels skid): a fifth of the turn is typical.
  double sigma_xy_per_m = 0.05;
  double sigma_xy_floor_m = 0.005;
  double sigma_yaw_per_rad = 0.2;
  double sigma_yaw_per_m = 0.02;
  double sigma_yaw_floor_rad = 0.002;
  /// The search before ICP for a prior too uncertain for ICP alone.
  IcpOdometrySearchOptions search;
  /// Self-calibration of the odometry's heading drift from the clear matches' corrections: where
  /// the odometry stands in for the scans (a failed match, a scan with no points, a degenerate
  /// direction) it stands in with its systematic drift taken out. Wheels a fraction of a percent
  /// apart turn a robot a degree per metre; ten metres without a usable scan (an open square, a
  /// black facade) would otherwise cost ten degrees that no later match on new ground repairs.
  /// The match itself still starts from the raw odometry. On by default (docs/estimators.md,
  /// icp-odometry: the figures with and without it).
  OdometryCalibrationOptions calibration = {.enabled = true};

  /// The noise model's standard deviations (x and y, yaw) of `increment`, before any measured
  /// noise scales them (sigma_xy_* and sigma_yaw_* above).
  Eigen::Vector2d IncrementSigmas(const Pose2& increment) const;
  /// The same for a stretch of increments summing to this distance and these absolute turns.
  Eigen::Vector2d StretchSigmas(double distance_m, double turn_rad) const;

  /// One message per broken rule, keys relative to this struct ("icp.", "points." nested).
  std::vector<std::string> Validate() const;
};

/// How IcpOdometry placed one scan.
enum class IcpOdometryOutcome {
  kFirstScan,    ///< the first scan: the origin, the first keyframe
  kMatched,      ///< the ICP match
  kDegenerate,   ///< the match along its well-constrained directions, the prior along the rest
  kMatchFailed,  ///< ICP failed (too few pairs, low score, too far from the prior): the prior
  kNoPoints,     ///< the scan had no usable points: the prior
};

/// One step of IcpOdometry.
struct IcpOdometryStep {
  Pose2 pose;  ///< odom_from_base of the scan
  /// Covariance of (x, y, yaw) of `pose` given the local map: the match's (IcpMatcher's Hessian
  /// estimate; huge along a degenerate direction), or the increment's noise model on a fallback.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  IcpOdometryOutcome outcome = IcpOdometryOutcome::kFirstScan;
  double score = 0.0;  ///< the match's score (IcpMatcher's inlier share) when it was used
  Pose2 prior;         ///< odom_from_base the scan was matched from (the odometry increment's)
  /// The prior's search window (x and y in m, yaw in rad): +-sigmas of its measured noise.
  Eigen::Vector2d window = Eigen::Vector2d::Zero();
  bool searched = false;        ///< a correlative search ran before ICP for this scan ...
  bool search_chosen = false;   ///< ... and its match replaced the one from the prior
  bool search_widened = false;  ///< the prior was doubted: the search ran over the wide window
  bool keyframe = false;        ///< the scan joined the local map
  int keyframe_id = -1;         ///< its number as a keyframe (0, 1, ...); -1 when it did not join
  /// When it joined: the share in the map's frame (FrameWeights, at the scan's pose) of every
  /// keyframe in the map it was matched against, as this scan saw it; what moves the frame
  /// (KeyframeErrors). Empty for point-to-point ICP.
  std::vector<KeyframeShareOf> frame_weights;
};

/// How many scans ended in each outcome.
struct IcpOdometryCounts {
  int scans = 0;
  int matched = 0;
  int degenerate = 0;
  int failed = 0;
  int no_points = 0;
  int searched = 0;       ///< scans searched correlatively before ICP
  int search_chosen = 0;  ///< ... whose searched match replaced the one from the prior
  int widened = 0;        ///< scans searched over the wide window (the prior doubted)
};

/// Scan-to-local-map ICP odometry with the wheel odometry as the prior: each scan is matched by
/// point-to-line ICP (Censi 2008) against the points of the last N keyframes, expressed in the odom
/// frame, starting from the previous pose composed with the odometry increment. When the match
/// fails the prior stands; when it is degenerate along a direction (a corridor's axis: the
/// covariance's eigenvalue above the threshold) the prior stands along that direction only. Both
/// are counted. The core of the `icp-odometry` estimator. Deterministic; not thread-safe.
class IcpOdometry {
 public:
  explicit IcpOdometry(const IcpOdometryOptions& options);

  /// Places `scan`, taken after the robot moved by `odometry_increment` (base frame at the previous
  /// scan to base frame at this one, from the wheel odometry; ignored for the first scan).
  /// `odometry_gap_s`: how long the odometry was silent before the scan (search.gap_s).
  IcpOdometryStep Add(const LaserScan& scan, const Pose2& odometry_increment,
                      double odometry_gap_s = 0.0);
  /// Places `scan` from several candidate increments, the first the prior (a motion prediction)
  /// and the others seeds for ICP: the match from each that passes the gates, a seed's replacing
  /// the best so far only when it scores better by search.min_gain; the search, the fallback and
  /// the degenerate directions keep to the prior. One increment: exactly Add(scan, increment).
  IcpOdometryStep Add(const LaserScan& scan, const std::vector<Pose2>& increments,
                      double odometry_gap_s = 0.0);

  const Pose2& pose() const { return pose_; }
  /// The odometry's noise as measured so far, in units of the noise model's sigma (x and y, yaw):
  /// 1 until clear matches say the prior is worse than the model.
  const Eigen::Vector2d& noise_scale() const { return noise_scale_; }
  const IcpOdometryCounts& counts() const { return counts_; }
  /// The odometry's heading drift as fitted so far (OdometryCalibration).
  const OdometryCalibration& calibration() const { return calibration_; }
  /// Points of the current local map, odom frame.
  const std::vector<Eigen::Vector2d>& local_map() const;

 private:
  struct Keyframe {
    int id = 0;
    std::vector<Eigen::Vector2d> points;  // odom frame
  };
  /// Adds a keyframe at `pose`; its number and the shares of the map it joined, as its scan saw
  /// them (IcpOdometryStep::frame_weights).
  std::pair<int, std::vector<KeyframeShareOf>> AddKeyframe(
      const std::vector<Eigen::Vector2d>& points_base, const Pose2& pose);
  /// Counts one scan's outcome.
  void Count(IcpOdometryOutcome outcome);
  /// After pose_ took a scan's placement: holds a blind scan out of the local map while its
  /// stretch is searchable (search.blind_scans), else ends the stretch; whether it held it.
  bool HoldIfBlind(IcpOdometryOutcome outcome, const std::vector<Eigen::Vector2d>& points,
                   const Pose2& increment, bool after_gap);
  /// The held scans join the local map where the wheels placed them.
  void JoinHeldScans();
  /// The match that ends a blind stretch: `held_map_match` (against the map without the held
  /// scans, over the stretch's window) or ICP from `prior` against the map with the held scans,
  /// the better score (within search.min_gain, the better posterior); in the second case the held
  /// scans join the map, else they are dropped.
  std::optional<MatchResult> EndBlindStretch(const std::vector<Eigen::Vector2d>& points,
                                             const Pose2& prior, const Pose2& increment,
                                             std::optional<MatchResult> held_map_match);
  /// The increment's noise model, scaled by the measured noise, in the previous base frame.
  Eigen::Matrix3d IncrementCovariance(const Pose2& increment) const;
  /// The search window (x and y, yaw) of `increment`'s prior: +-sigmas of its measured noise,
  /// over the blind stretch before it as well (search.blind_scans).
  Eigen::Vector2d SearchWindow(const Pose2& increment) const;
  /// The noise model's sigmas (x and y, yaw), scaled by the measured noise, over the blind
  /// stretch and `increment` after it.
  Eigen::Vector2d StretchNoise(const Pose2& increment) const;
  /// Whether a failed scan stays out of the local map: its blind stretch is still searchable.
  bool HoldsMapWhileBlind(const Pose2& increment) const;
  /// The better of `from_prior` (ICP's match from `prior`, nothing when it failed) and a
  /// correlative search within `window` of `prior` refined by ICP, when the window is beyond ICP's
  /// basin or ICP failed.
  std::optional<MatchResult> SearchedMatch(const std::vector<Eigen::Vector2d>& points,
                                           const Pose2& prior, const Eigen::Vector2d& window,
                                           std::optional<MatchResult> from_prior);
  /// Updates noise_scale_ from a clear match's correction of the prior.
  void MeasureNoise(const Pose2& prior, const Pose2& matched, const Pose2& increment);
  /// The match's correction of `fallback`'s position (odom frame) less its part along the
  /// directions where the odometry stands (a degenerate covariance, a weakly seen direction with a
  /// correction beyond the gate); `degenerate` set when any was taken out.
  Eigen::Vector2d KeptCorrection(const MatchResult& match, const Pose2& fallback,
                                 const Eigen::Matrix3d& prior_covariance,
                                 const std::vector<Eigen::Vector2d>& points,
                                 bool* degenerate) const;
  /// The local map's match from `prior`, or nothing when it fails the score or the correction
  /// gates (max_correction_m and _rad, or `window` where that is wider).
  std::optional<MatchResult> GatedMatch(const std::vector<Eigen::Vector2d>& points,
                                        const Pose2& prior, const Eigen::Vector2d& window) const;
  /// Whether `match` passes the score and the correction gates (GatedMatch).
  bool WithinGates(const MatchResult& match, const Pose2& prior,
                   const Eigen::Vector2d& window) const;

  IcpOdometryOptions options_;
  Pose2 pose_;
  Pose2 last_keyframe_;
  bool started_ = false;
  std::deque<Keyframe> keyframes_;  // oldest first
  LocalMapPoints map_;              // the matcher's reference, with each point's keyframe
  int next_keyframe_id_ = 0;
  std::optional<IcpMatcher> matcher_;
  // The local map's raster and its correlative matcher, built when a search first needs them
  // after each keyframe.
  std::optional<PointRaster> raster_;
  std::optional<CorrelativeMatcher> searcher_;
  OdometryCalibration calibration_;
  bool last_matched_ = false;  // the previous scan's match was clear (kMatched)
  // The scans the odometry placed alone since the last match whose points stayed out of the
  // local map (search.blind_scans): how many, their points, and the odometry's travel and
  // absolute turns over them.
  struct HeldScan {
    std::vector<Eigen::Vector2d> points_base;
    Pose2 pose;  // odom frame, the wheels' placement
  };
  int blind_scans_ = 0;
  std::vector<HeldScan> held_;
  double blind_distance_m_ = 0.0;
  double blind_turn_rad_ = 0.0;
  Eigen::Vector2d noise_scale_{1.0, 1.0};
  Eigen::Vector2d noise_mean_size_{1.0, 1.0};
  IcpOdometryCounts counts_;
};

}  // namespace slamrig::slam
