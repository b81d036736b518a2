#include "slam/pipeline/dead_reckoning_estimator.h"

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> DeadReckoningOptions::Validate() const {
  Rules rules;
  rules.Nested("map", map.Validate()).Nested("noise", noise.Validate());
  return rules.errors();
}

namespace {

WheelOdometryOptions WheelsOf(const EstimatorContext& context) {
  WheelOdometryOptions options;
  options.robot = context.robot;
  options.use_gyro = context.use_gyro;
  return options;
}

}  // namespace

DeadReckoningEstimator::DeadReckoningEstimator(const DeadReckoningOptions& options,
                                               const EstimatorContext& context)
    : map_(options.map), noise_(options.noise), wheels_(WheelsOf(context)) {
  noise_.ResetPose(Pose2());
}

void DeadReckoningEstimator::AddRecord(const Record& record) {
  last_record_was_ticks_ = false;
  if (const auto* imu = std::get_if<ImuSample>(&record)) wheels_.AddImu(*imu);
  if (const auto* ticks = std::get_if<WheelTicks>(&record)) {
    wheels_.AddTicks(*ticks);
    last_record_was_ticks_ = true;
  }
}

std::optional<ScanEstimate> DeadReckoningEstimator::RecordEstimate() const {
  if (!last_record_was_ticks_) return std::nullopt;
  ScanEstimate estimate;
  estimate.pose = wheels_.pose();
  return estimate;
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
