#pragma once

#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/icp_matcher.h"
#include "slam/matching/matching_fields.h"
#include "slam/matching/scan_points.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

/// Options of the `scan-to-scan` algorithm.
struct ScanToScanOptions {
  OccupancyGridOptions map;
  ScanPointsOptions points;
  IcpOptions icp;
  /// A match that differs from the odometry's guess by more than this is refused and the guess
  /// kept (m, rad).
  double max_correction_m = 0.2;
  double max_correction_rad = 0.2;
  /// A scan becomes the new keyframe once it is this far from the last one (m, rad).
  double keyframe_distance_m = 0.3;
  double keyframe_angle_rad = 0.2;

  /// One message per broken rule ("max_correction_m = 0; must be > 0").
  std::vector<std::string> Validate() const {
    std::vector<std::string> errors = PrefixErrors("map", map.Validate());
    AppendErrors(&errors, points.Validate());
    AppendErrors(&errors, icp.Validate());
    if (!(max_correction_m > 0)) {
      errors.push_back(RuleViolation("max_correction_m", max_correction_m, "must be > 0"));
    }
    if (!(max_correction_rad > 0)) {
      errors.push_back(RuleViolation("max_correction_rad", max_correction_rad, "must be > 0"));
    }
    if (!(keyframe_distance_m >= 0)) {
      errors.push_back(RuleViolation("keyframe_distance_m", keyframe_distance_m, "must be >= 0"));
    }
    if (!(keyframe_angle_rad >= 0)) {
      errors.push_back(RuleViolation("keyframe_angle_rad", keyframe_angle_rad, "must be >= 0"));
    }
    return errors;
  }
};

/// The field table of ScanToScanOptions: what a scenario's `slam:` entry, `--set`, config.yaml
/// and metrics.json read and write.
template <typename V>
void VisitFields(V& v, ScanToScanOptions& o) {
  v.Struct("map", o.map);
  v.Struct("points", o.points);
  v.Struct("icp", o.icp);
  v("max_correction_m", o.max_correction_m);
  v("max_correction_rad", o.max_correction_rad);
  v("keyframe_distance_m", o.keyframe_distance_m);
  v("keyframe_angle_rad", o.keyframe_angle_rad);
}

/// Odometry corrected by scan-to-scan ICP: each scan is matched against the last keyframe's scan
/// (Censi 2008, point-to-line by default) from the odometry's guess, the match is taken when it
/// stays within max_correction_* of the guess, and the map is built along the result. Matching
/// against a keyframe rather than the previous scan keeps the matches' small errors from adding
/// up at the scan rate. It never revises its past.
class ScanToScanEstimator final : public Estimator {
 public:
  ScanToScanEstimator(const ScanToScanOptions& options, const EstimatorContext& /*context*/)
      : options_(options), map_(options.map) {}

  ScanEstimate AddScan(const SyncedScan& scan) override {
    if (keyframe_) {
      // Where the odometry puts this scan in the keyframe's frame.
      const Pose2 guess = from_keyframe_ * scan.increment;
      const std::optional<MatchResult> match =
          IcpMatcher::MatchScans(options_.icp, options_.points, *keyframe_, scan.scan, guess);
      if (match && WithinCorrection(match->pose, guess)) {
        from_keyframe_ = match->pose;
        ++matched_;
      } else {
        from_keyframe_ = guess;
        ++refused_;
      }
    }
    const Pose2 pose = keyframe_pose_ * from_keyframe_;
    if (!keyframe_ || from_keyframe_.translation().norm() >= options_.keyframe_distance_m ||
        std::abs(from_keyframe_.theta()) >= options_.keyframe_angle_rad) {
      keyframe_ = scan.scan;
      keyframe_pose_ = pose;
      from_keyframe_ = Pose2();
    }
    map_.InsertScan(scan.scan, pose);
    ScanEstimate estimate;
    estimate.pose = pose;
    return estimate;
  }

  const OccupancyGrid& map() const override { return map_; }

  /// The names Statistics() reports: the algorithm table declares them, so that metrics.json
  /// has them and a scenario's `expect:` takes `matched_min` and the like.
  static std::vector<std::string> StatisticNames() { return {"matched", "refused"}; }
  std::map<std::string, double> Statistics() const override {
    return {{"matched", matched_}, {"refused", refused_}};
  }

 private:
  bool WithinCorrection(const Pose2& matched, const Pose2& guess) const {
    const Pose2 correction = guess.Between(matched);
    return correction.translation().norm() <= options_.max_correction_m &&
           std::abs(correction.theta()) <= options_.max_correction_rad;
  }

  ScanToScanOptions options_;
  OccupancyGrid map_;
  std::optional<LaserScan> keyframe_;  ///< the last keyframe's scan
  Pose2 keyframe_pose_;                ///< its pose in the estimator's frame
  Pose2 from_keyframe_;                ///< this scan's pose in the keyframe's frame
  double matched_ = 0;
  double refused_ = 0;
};

}  // namespace slamrig::slam
