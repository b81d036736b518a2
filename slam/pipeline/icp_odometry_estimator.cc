#include "slam/pipeline/icp_odometry_estimator.h"

#include <string>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> IcpOdometryEstimatorOptions::Validate() const {
  // The odometry's keys sit at the top level of this table.
  Rules rules;
  rules.Nested("", icp_odometry.Validate()).Nested("map", map.Validate());
  return rules.errors();
}

IcpOdometryEstimator::IcpOdometryEstimator(const IcpOdometryEstimatorOptions& options,
                                           const EstimatorContext& /*context*/)
    : odometry_(options.icp_odometry), map_(options.map) {}

ScanEstimate IcpOdometryEstimator::AddScan(const SyncedScan& scan) {
  const IcpOdometryStep step = odometry_.Add(scan.scan, scan.increment, scan.odometry_gap_s);
  map_.InsertScan(scan.scan, step.pose);
  ScanEstimate estimate;
  estimate.pose = step.pose;
  const bool lost = front_end_health_.Judge(step, &estimate.trace);
  health_.Add(lost);
  estimate.lost = lost;
  return estimate;
}

const std::vector<std::string>& IcpOdometryEstimator::StatisticNames() {
  static const std::vector<std::string> names = {"matched", "degenerate", "failed",
                                                 "widened", "lost",       "diverged"};
  return names;
}

std::map<std::string, double> IcpOdometryEstimator::Statistics() const {
  const IcpOdometryCounts& c = odometry_.counts();
  return {{"matched", c.matched},
          {"degenerate", c.degenerate},
          {"failed", c.failed + c.no_points},
          {"widened", c.widened},
          {"lost", health_.losses()},
          // Every loss stays in the estimate: an odometry closes no loops that could measure it.
          {"diverged", health_.Diverged() || health_.losses() > 0 ? 1.0 : 0.0}};
}

}  // namespace slamrig::slam
