#include "slam/pipeline/dead_reckoning_estimator.h"

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> DeadReckoningOptions::Validate() const {
  return PrefixErrors("map", map.Validate());
}

DeadReckoningEstimator::DeadReckoningEstimator(const DeadReckoningOptions& options,
                                               const EstimatorContext& /*context*/)
    : map_(options.map) {}

ScanEstimate DeadReckoningEstimator::AddScan(const SyncedScan& scan) {
  if (started_) pose_ = pose_ * scan.increment;
  started_ = true;
  map_.InsertScan(scan.scan, pose_);
  return {pose_, std::nullopt, {}};
}

}  // namespace slamrig::slam
