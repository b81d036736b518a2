#pragma once

#include <optional>

#include "slam/matching/icp_odometry.h"
#include "slam/odometry/scan_sync.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The motion between scans of a log without odometry (`odometry: {source: none}`, or a log
/// whose odometry is missing): each scan is matched against a local map of the last keyframes
/// (IcpOdometry) from a constant-velocity prediction (the last matched increment, scaled down to
/// a shorter interval, never stretched beyond itself) and seeds around it (standing still, turned
/// or moved by a few decimetres, stretched to a longer interval), then a correlative search of
/// +-1.2 m and +-0.75 rad at least around the prediction; the best match is kept, the prediction
/// winning ties (along a corridor the scan cannot tell how far the robot went: the prediction
/// says it, not the seed that overlaps the map best, standing still). Where every match fails the
/// prediction stands and the velocity is kept; where the match is degenerate, along the
/// degenerate direction only. Every estimator then takes the result as its odometry, with its own
/// motion noise around it. Deterministic.
class ScanMatchedOdometry {
 public:
  ScanMatchedOdometry();

  /// `scan` with odom_from_base, increment, distance_m and yaw_change_rad from the match (a
  /// scan from a source without odometry: identity increments).
  SyncedScan Apply(const SyncedScan& scan);

  const IcpOdometryCounts& counts() const { return odometry_.counts(); }

 private:
  IcpOdometry odometry_;
  Pose2 pose_;
  Pose2 last_increment_;    // the last matched increment ...
  double last_dt_s_ = 0.0;  // ... and its interval (0: none matched yet)
  bool started_ = false;
};

}  // namespace slamrig::slam
