#pragma once

#include <optional>
#include <string>
#include <vector>

#include "slam/fusion/pose_ekf.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"

namespace slamrig::slam {

/// Options of dead reckoning: the map built along the odometry, and the odometry's noise for
/// the propagated covariance (PoseEkf's increment model: the `increment_*` keys of `noise`).
struct DeadReckoningOptions {
  OccupancyGridOptions map;
  PoseEkfOptions noise;

  /// One message per broken rule ("map.resolution_m = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

/// The field table of DeadReckoningOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, DeadReckoningOptions& o) {
  v.Struct("map", o.map);
  v.Struct("noise", o.noise);
}

/// Dead reckoning: the odometry increments composed from the first scan, with the map built
/// along them, and the odometry noise propagated into a covariance with every pose (so that its
/// NEES can be shown). The baseline every SLAM result is compared with. Wheel ticks are also
/// integrated as they arrive (WheelOdometry, with the gyro as odometry.use_gyro says), one pose
/// per ticks record: the record-rate trajectory, all there is on a log without scans.
class DeadReckoningEstimator final : public Estimator {
 public:
  DeadReckoningEstimator(const DeadReckoningOptions& options, const EstimatorContext& context);

  void AddRecord(const Record& record) override;
  /// The wheel odometry's pose after each ticks record (no covariance).
  std::optional<ScanEstimate> RecordEstimate() const override;
  ScanEstimate AddScan(const SyncedScan& scan) override;
  const OccupancyGrid& map() const override { return map_; }

 private:
  OccupancyGrid map_;
  PoseEkf noise_;
  bool started_ = false;
  WheelOdometry wheels_;
  bool last_record_was_ticks_ = false;
};

}  // namespace slamrig::slam
