#pragma once

#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"

namespace slamrig::slam {

/// Options of dead reckoning: only the map built along the odometry.
struct DeadReckoningOptions {
  OccupancyGridOptions map;

  /// One message per broken rule ("map.resolution_m = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

/// The field table of DeadReckoningOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, DeadReckoningOptions& o) {
  v.Struct("map", o.map);
}

/// Dead reckoning: the odometry increments composed from the first scan, with the map built
/// along them. The baseline every SLAM result is compared with.
class DeadReckoningEstimator final : public Estimator {
 public:
  DeadReckoningEstimator(const DeadReckoningOptions& options, const EstimatorContext& context);

  ScanEstimate AddScan(const SyncedScan& scan) override;
  const OccupancyGrid& map() const override { return map_; }

 private:
  OccupancyGrid map_;
  Pose2 pose_;
  bool started_ = false;
};

}  // namespace slamrig::slam
