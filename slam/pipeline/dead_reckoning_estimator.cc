#include "slam/pipeline/dead_reckoning_estimator.h"

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> DeadReckoningOptions::Validate() const {
  std::vector<std::string> errors = PrefixErrors("map", map.Validate());
  AppendErrors(&errors, PrefixErrors("noise", noise.Validate()));
  return errors;
}

DeadReckoningEstimator::DeadReckoningEstimator(const DeadReckoningOptions& options,
                                               const EstimatorContext& /*context*/)
    : map_(options.map), noise_(options.noise) {
  noise_.ResetPose(Pose2());
}

ScanEstimate DeadReckoningEstimator::AddScan(const SyncedScan& scan) {
  if (started_) {
    noise_.PredictIncrement(scan.increment, scan.increment.translation().norm(),
                            scan.increment.theta());
  }
  started_ = true;
  ScanEstimate estimate;
  estimate.pose = noise_.pose();
  estimate.covariance = noise_.PoseCovariance();
  map_.InsertScan(scan.scan, estimate.pose);
  return estimate;
}

}  // namespace slamrig::slam
