#pragma once

#include <map>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/icp_odometry.h"
#include "slam/matching/matching_fields.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/health.h"

namespace slamrig::slam {

/// Options of the `icp-odometry` algorithm: the scan-to-local-map odometry and the map built
/// along its poses.
struct IcpOdometryEstimatorOptions {
  IcpOdometryOptions icp_odometry;
  OccupancyGridOptions map;

  /// One message per broken rule ("icp_odometry.min_score = 2; must be in [0, 1]").
  std::vector<std::string> Validate() const;
};

/// The field table of IcpOdometryEstimatorOptions: the odometry's keys at the top level.
template <typename V>
void VisitFields(V& v, IcpOdometryEstimatorOptions& o) {
  VisitFields(v, o.icp_odometry);
  v.Struct("map", o.map);
}

/// Scan-to-local-map ICP odometry (IcpOdometry: Censi 2008 point-to-line ICP against the last
/// keyframes, the wheel odometry as prior and fallback) behind the Estimator interface, with the
/// map built along its poses. It never revises its past.
class IcpOdometryEstimator final : public Estimator {
 public:
  IcpOdometryEstimator(const IcpOdometryEstimatorOptions& options, const EstimatorContext& context);

  ScanEstimate AddScan(const SyncedScan& scan) override;
  const OccupancyGrid& map() const override { return map_; }
  /// matched, degenerate, failed (match failures and scans without points) scan counts; lost
  /// (losses of the front end, FrontEndHealth) and diverged (any loss: nothing repairs one).
  std::map<std::string, double> Statistics() const override;
  /// The names Statistics() reports, without an instance: the algorithm table's list (and so
  /// the expectations'); EstimatorRunner checks every run's Statistics() against it.
  static const std::vector<std::string>& StatisticNames();

 private:
  IcpOdometry odometry_;
  OccupancyGrid map_;
  FrontEndHealth front_end_health_;
  HealthRecord health_;
};

}  // namespace slamrig::slam
