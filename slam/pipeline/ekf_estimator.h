#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/fusion/pose_ekf.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/matching/icp_odometry.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"

namespace slamrig::slam {

/// Options of the `ekf` estimator: the filter's noise, how scan matches enter it, the map.
struct EkfOptions {
  PoseEkfOptions filter;      ///< motion and bias noise (its keys sit at this level)
  bool scan_matching = true;  ///< correct with scan-to-local-map ICP increments
  /// The ICP covariance is multiplied by this (a Hessian estimate is optimistic) ...
  double match_covariance_scale = 4.0;
  /// ... and a floor added: standard deviations of the increment's x, y and yaw.
  double match_sigma_floor_xy_m = 0.005;
  double match_sigma_floor_yaw_rad = 0.002;
  /// Also update on matches IcpOdometry calls degenerate (the prior fills their weak direction).
  bool update_on_degenerate = false;
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
  v("update_on_degenerate", o.update_on_degenerate);
  v.Struct("map", o.map);
}

/// EKF pose fusion (PoseEkf): wheel encoders and the gyro predict as their records arrive
/// (odometry-pose increments at the scans when the source has no encoders), gyro samples at
/// standstill measure the gyro bias, and each scan's IcpOdometry match against the local map
/// corrects the increment since the previous scan with the match's covariance. Reports the pose
/// covariance with every pose, the NIS of each scan update as the trace `nis`.
class EkfEstimator final : public Estimator {
 public:
  EkfEstimator(const EkfOptions& options, const EstimatorContext& context);

  void AddRecord(const Record& record) override;
  /// The pose and covariance after each wheel-ticks record (the record-rate trajectory).
  std::optional<ScanEstimate> RecordEstimate() const override;
  ScanEstimate AddScan(const SyncedScan& scan) override;
  const OccupancyGrid& map() const override { return map_; }
  std::map<std::string, double> Statistics() const override;

 private:
  void AddImu(const ImuSample& imu);
  void AddTicks(const WheelTicks& ticks);

  EkfOptions options_;
  DiffDriveParams robot_;
  PoseEkf ekf_;
  IcpOdometry icp_;
  OccupancyGrid map_;
  Pose2 icp_previous_;
  int scans_ = 0;
  bool saw_ticks_ = false;
  bool last_record_was_ticks_ = false;
  int still_intervals_ = 0;  // consecutive encoder intervals without a tick
  std::optional<Time> last_imu_time_;
  bool gyro_since_ticks_ = false;
  double gyro_yaw_since_ticks_ = 0.0;
  int scan_updates_ = 0;
  int zero_rate_updates_ = 0;
  double nis_sum_ = 0.0;
};

}  // namespace slamrig::slam
