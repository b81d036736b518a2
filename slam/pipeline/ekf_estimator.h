#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/fusion/pose_ekf.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/matching/icp_odometry.h"
#include "slam/matching/map_frame_drift.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/health.h"
#include "slam/pipeline/wheel_gyro_feed.h"

namespace slamrig::slam {

/// Options of the `ekf` estimator: the filter's noise, how scan matches enter it, the map.
struct EkfOptions {
  PoseEkfOptions filter;      ///< motion and bias noise (its keys sit at this level)
  bool scan_matching = true;  ///< correct with scan-to-local-map ICP increments
  /// The ICP covariance is multiplied by this ...
  double match_covariance_scale = 1.0;
  /// ... and a floor added: standard deviations of the match's x, y and yaw against its local
  /// map (what a match errs by beyond its Hessian estimate; set so that the mean NIS on the
  /// office loop is near its expected 3, a check that needs no truth).
  double match_sigma_floor_xy_m = 0.0011;
  double match_sigma_floor_yaw_rad = 0.00035;
  /// Without encoders (odometry-pose increments) the keyframe-to-keyframe increments correct
  /// through the clone instead, with these floors (standard deviations of the increment).
  double increment_sigma_floor_xy_m = 0.0015;
  double increment_sigma_floor_yaw_rad = 0.0005;
  /// The Hessian's covariance ignores the local map's own noise and the correlation of
  /// neighbouring residuals, so it understates the spread more the noisier the lidar: scale the
  /// match covariance by a factor (at least 1) adapted so that the updates' NIS averages its
  /// dimension (Mehra 1972's covariance matching, a stochastic-approximation step on the log of
  /// the factor per update; updates whose motion was inflated for a slip are left out).
  bool adaptive_match_covariance = true;
  /// The local map's frame drifts as keyframes join it, each placed with its match's error. With
  /// the matcher's shares (point-to-line ICP) the drift is derived (derived_map_drift); without
  /// them (point-to-point ICP) or with derived_map_drift off, the map's pose moves by this share
  /// of each keyframe's match error (standard deviations), a fitted constant: 0.45 leaves the
  /// office loop optimistic (README, "EKF").
  double map_drift_share = 0.45;
  /// The frame's drift from the local map's composition (KeyframeErrors,
  /// slam/matching/map_frame_drift.h): a match lands at the information-weighted mean of its
  /// keyframes' errors, weighted by the points it pairs with; every keyframe was placed at the
  /// frame its own match saw plus that match's error, so their errors are kept jointly, and the
  /// frame seen by each keyframe's match moves from the last one's by the change of the shares,
  /// given the frame before.
  bool derived_map_drift = true;
  /// Also update on matches IcpOdometry calls degenerate (the prior fills their weak direction).
  bool update_on_degenerate = false;
  /// Update once per ICP keyframe; false: at every matched scan (consecutive scans meet the same
  /// map from nearly the same place, so their errors are not independent: the covariance comes
  /// out optimistic).
  bool keyframe_updates = true;
  /// A match whose NIS exceeds this (chi2_3 at 0.999) says the motion model failed (a wheel
  /// slipped on ice): the motion's covariance is inflated until it does not. 0: never.
  double slip_gate = 16.27;
  /// Where the source states its gyro's noise (a simulated robot's file), model that instead of
  /// gyro_sigma_rad_s and gyro_bias_walk_rad_s_sqrt_s: a sample's sigma is the noise density
  /// times sqrt(rate), the bias walk the file's random walk. Off by default: on the office loop
  /// (one lap, 20 seeds, with the fitted map_drift_share) the honest gyro moves the ANEES from 4.5
  /// to 5.5 and the mean NIS from 3.6 to 4.3, because map_drift_share was fitted with the default's
  /// 6x gyro noise standing in for unmodelled error (see README, "EKF").
  bool gyro_noise_from_robot = false;
  OccupancyGridOptions map;

  /// One message per broken rule ("match_covariance_scale = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

/// The field table of EkfOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, EkfOptions& o) {
  VisitFields(v, o.filter);
  v("scan_matching", o.scan_matching);
  v("match_covariance_scale", o.match_covariance_scale);
  v("match_sigma_floor_xy_m", o.match_sigma_floor_xy_m);
  v("match_sigma_floor_yaw_rad", o.match_sigma_floor_yaw_rad);
  v("increment_sigma_floor_xy_m", o.increment_sigma_floor_xy_m);
  v("increment_sigma_floor_yaw_rad", o.increment_sigma_floor_yaw_rad);
  v("adaptive_match_covariance", o.adaptive_match_covariance);
  v("map_drift_share", o.map_drift_share);
  v("derived_map_drift", o.derived_map_drift);
  v("update_on_degenerate", o.update_on_degenerate);
  v("keyframe_updates", o.keyframe_updates);
  v("slip_gate", o.slip_gate);
  v("gyro_noise_from_robot", o.gyro_noise_from_robot);
  v.Struct("map", o.map);
}

/// EKF pose fusion (PoseEkf): wheel encoders and the gyro predict as their records arrive
/// (odometry-pose increments at the scans when the source has no encoders), gyro samples at
/// standstill measure the gyro bias (and turns its scale error), and IcpOdometry matches each
/// scan against its local map. At each ICP keyframe the match's pose in the matcher's frame
/// corrects the filter through the matcher's frame, a state that drifts as keyframes join the
/// local map (PoseEkf::UpdateMatcherPose): the matches' errors against the map are nearly
/// independent, where the increments between keyframes are not (two consecutive increments share
/// the keyframe between them with opposite signs, so their errors cancel along the path; treated
/// as independent, they make the covariance grow as a random walk the error does not follow).
/// A keyframe whose match was unusable joins the map where the odometry put it, so the frame is
/// anchored anew at the next usable match, which then measures nothing but the frame.
/// Updating once per keyframe keeps the updates' errors nearly independent: the scans between two
/// keyframes meet the same map from nearly the same place. Reports the pose covariance with every
/// pose, the NIS of the latest scan update as the trace `nis`.
class EkfEstimator final : public Estimator {
 public:
  EkfEstimator(const EkfOptions& options, const EstimatorContext& context);

  void AddRecord(const Record& record) override;
  /// The pose and covariance after each wheel-ticks record (the record-rate trajectory).
  std::optional<ScanEstimate> RecordEstimate() const override;
  ScanEstimate AddScan(const SyncedScan& scan) override;
  const OccupancyGrid& map() const override { return map_; }
  std::map<std::string, double> Statistics() const override;
  /// The names Statistics() reports, without an instance: the algorithm table's list (and so
  /// the expectations'); EstimatorRunner checks every run's Statistics() against it.
  static const std::vector<std::string>& StatisticNames();

 private:
  /// Matches `scan` at the filter's current pose, updates, clones; the estimate at the scan.
  ScanEstimate Correct(const LaserScan& scan);
  /// The factor applied to the match covariance (the adapted one, at least 1).
  double MatchScale() const;

  EkfOptions options_;
  WheelGyroFeed<PoseEkf> feed_;
  PoseEkf ekf_;
  IcpOdometry icp_;
  OccupancyGrid map_;
  Pose2 previous_pose_;
  int scans_ = 0;
  bool last_record_was_ticks_ = false;
  int scan_updates_ = 0;
  int slip_inflations_ = 0;
  int keyframes_ = 0;
  Pose2 icp_keyframe_;     // the last keyframe's match (the increments' start, no encoders)
  bool anchored_ = false;  // the matcher's frame is tied to the filter's
  int anchors_ = 0;
  double log_match_scale_ = 0.0;  // the estimate of log(factor on the match covariance)
  double nis_sum_ = 0.0;
  double last_nis_ = 0.0;
  NisWindow nis_window_;
  HealthRecord health_;
  // The joint errors of the keyframes in the matcher's local map (derived_map_drift).
  KeyframeErrors keyframe_errors_;
};

}  // namespace slamrig::slam
