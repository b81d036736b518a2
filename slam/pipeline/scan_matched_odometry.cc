#include "slam/pipeline/scan_matched_odometry.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace slamrig::slam {
namespace {

// IcpOdometry's defaults with a prior that is only a prediction: a robot that changes speed or
// turns between two scans is off it by decimetres and tenths of a radian however short the
// interval, so the model's floors are wide (the search window +-3 sigma: 1.2 m and 0.75 rad at
// least) and the search runs on every scan. No online noise measurement: the prediction's errors
// are the robot's changes of mind, not a noise level to learn, nor a wheel's drift to calibrate.
IcpOdometryOptions WideGates() {
  IcpOdometryOptions o;
  o.max_correction_m = 1.0;
  o.max_correction_rad = 0.6;
  o.sigma_xy_per_m = 0.2;
  o.sigma_xy_floor_m = 0.4;
  o.sigma_yaw_per_rad = 0.2;
  o.sigma_yaw_floor_rad = 0.25;
  o.search.sigmas = 3.0;
  o.search.adapt_rate = 0.0;
  // The windows are the prediction's own, every scan: a failed or far-moved match is a robot's
  // change of mind, not a wheel's under-reported turn to search wider for.
  o.search.wide_window_rad = 0.0;
  // For the same reason a failed scan joins the map where the prediction placed it: the next
  // prediction is no better for the held map.
  o.search.blind_scans = 0;
  o.calibration.enabled = false;
  return o;
}

Pose2 Scaled(const Pose2& increment, double k) {
  return Pose2(k * increment.x(), k * increment.y(), k * increment.theta());
}

}  // namespace

ScanMatchedOdometry::ScanMatchedOdometry() : odometry_(WideGates()) {}

SyncedScan ScanMatchedOdometry::Apply(const SyncedScan& scan) {
  SyncedScan out = scan;
  // Constant velocity: the last matched increment, scaled down to a shorter interval but never
  // stretched beyond itself (a log whose scans are triggered by motion, as the corrected CARMEN
  // logs are, has intervals that vary while the motion per scan does not); the stretched one, at
  // most twice, is a further candidate (a time-triggered log that lost a scan). A failed match
  // leaves the velocity as the last match measured it: the robot coasts. Predicted still, it is
  // lost for good once it has driven beyond the local map, every later match failing in turn
  // (acapulco without odometry: 54 scans in a row from scan 274, 11.5 m;
  // docs/studies/no-odometry.md).
  Pose2 prediction;
  std::optional<Pose2> stretched;
  if (last_dt_s_ > 0.0 && scan.dt_s > 0.0) {
    const double ratio = scan.dt_s / last_dt_s_;
    prediction = Scaled(last_increment_, std::min(ratio, 1.0));
    if (ratio > 1.0) stretched = Scaled(last_increment_, std::min(ratio, 2.0));
  }
  // The prediction first (IcpOdometry's prior, kept where the scan cannot tell), then standing
  // still, and the prediction turned or moved by what a robot may change between two scans: a
  // seed wins over the prediction only by a clearly better match.
  std::vector<Pose2> candidates = {prediction, Pose2()};
  for (const double turn : {-0.3, 0.3}) {
    candidates.push_back(Pose2(prediction.x(), prediction.y(), prediction.theta() + turn));
  }
  for (const double step : {-0.3, 0.3}) {
    candidates.push_back(prediction * Pose2(step, 0.0, 0.0));
  }
  if (stretched) candidates.push_back(*stretched);
  const IcpOdometryStep step = odometry_.Add(scan.scan, candidates);
  const Pose2 increment = started_ ? pose_.Between(step.pose) : Pose2();
  const bool matched = step.outcome == IcpOdometryOutcome::kMatched ||
                       step.outcome == IcpOdometryOutcome::kDegenerate;
  if (started_ && matched) {
    last_increment_ = increment;
    last_dt_s_ = scan.dt_s;
  }
  started_ = true;
  pose_ = step.pose;
  out.odom_from_base = step.pose;
  out.increment = increment;
  const double distance = increment.translation().norm();
  out.distance_m = increment.x() < 0.0 ? -distance : distance;
  out.yaw_change_rad = increment.theta();
  return out;
}

}  // namespace slamrig::slam
