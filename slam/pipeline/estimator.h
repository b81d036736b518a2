#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/odometry/scan_sync.h"
#include "slam/types/loop_closure.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// A named number an estimator reports after each scan, for plots over time (e.g. "neff").
struct TraceValue {
  std::string name;
  double value = 0.0;
};

/// What an estimator says about one scan.
struct ScanEstimate {
  Pose2 pose;                      ///< the online estimate of base_link at the scan's time
  std::optional<Pose2> mean_pose;  ///< a second estimate where there is one (a PF's mean)
  std::vector<TraceValue> trace;   ///< per-scan values for plots
  /// Covariance of (x, y, yaw) of `pose` in the estimator's frame (m^2, m rad, rad^2), where the
  /// estimator has one (a Kalman filter, propagated dead reckoning).
  std::optional<Eigen::Matrix3d> covariance;
  /// The estimator's own judgement of this scan by its documented rule (slam/pipeline/health.h):
  /// true when its health values say it is lost here; nullopt from an estimator that cannot
  /// judge itself (dead reckoning).
  std::optional<bool> lost;
};

/// A pose hypothesis with its normalised weight (a particle).
struct WeightedPose {
  Pose2 pose;
  double weight = 0.0;
};

/// An edge of a pose graph to draw: the positions of the two nodes it joins.
struct ViewEdge {
  Eigen::Vector2d from = Eigen::Vector2d::Zero();
  Eigen::Vector2d to = Eigen::Vector2d::Zero();
  bool loop_closure = false;  ///< a loop closure, else an odometry edge
};

/// A mapped point landmark (a pillar), in the estimator's frame.
struct LandmarkEstimate {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  ///< of position_m, m^2
};

/// One observation an estimator paired with a landmark (or started one from), so that its
/// associations can be scored against the truth.
struct LandmarkSighting {
  Time time;                                                ///< the scan's
  int landmark = -1;                                        ///< index into LandmarkMap::landmarks
  Eigen::Vector2d center_base_m = Eigen::Vector2d::Zero();  ///< the observed centre, base_link
};

/// A landmark estimator's map: the final landmarks and every sighting it used.
struct LandmarkMap {
  std::vector<LandmarkEstimate> landmarks;
  std::vector<LandmarkSighting> sightings;
};

/// What the live view (and `slamrig slam --clouds`) may show besides the pose and the map, in
/// the estimator's frame.
struct EstimatorView {
  std::vector<WeightedPose> particles;
  std::vector<ViewEdge> edges;  ///< a graph estimator's edges at its current estimate

  /// A landmark estimator's current map.
  std::vector<LandmarkEstimate> landmarks;
  /// The current pose's covariance (x, y, yaw), where the estimator has one.
  std::optional<Eigen::Matrix3d> pose_covariance;
};

/// The one interface every SLAM algorithm implements (dead reckoning, the particle filter, and
/// every algorithm after them). An EstimatorRunner feeds it: every record as it arrives through
/// AddRecord (for estimators that predict at sensor rates), and each laser scan, synchronised
/// with the odometry by a ScanSynchronizer, through AddScan; Finish() at the end of the data.
/// Frames: the estimator's own frame is base_link at the first scan (the identity pose there).
/// Implementations are deterministic: same records, same options, same bits.
class Estimator {
 public:
  virtual ~Estimator() = default;

  /// Every record in arrival order, before any scan it completes. Default: ignored.
  virtual void AddRecord(const Record& record) { (void)record; }
  /// The estimate right after the last AddRecord when that record moved it (an EKF predicting
  /// from wheel ticks), else nullopt (the default). The runner keeps these as the run's
  /// record-rate trajectory, which is all there is on a log without scans.
  virtual std::optional<ScanEstimate> RecordEstimate() const { return std::nullopt; }
  /// One synchronised scan; returns the online estimate at its time.
  virtual ScanEstimate AddScan(const SyncedScan& scan) = 0;
  /// The end of the data (a graph back end runs its final optimisation here).
  virtual void Finish() {}

  /// The final trajectory when the estimator revises its past (one pose per scan, in AddScan
  /// order); nullopt when it does not, and the online poses are final.
  virtual std::optional<std::vector<Pose2>> RevisedPoses() const { return std::nullopt; }
  /// The map, in the estimator's frame.
  virtual const OccupancyGrid& map() const = 0;
  /// Named statistics for metrics.json (e.g. "mean_neff", "resamples", "loop_closures").
  virtual std::map<std::string, double> Statistics() const { return {}; }
  /// The loop closures it accepted (scan indices in AddScan order), for scoring; default none.
  virtual std::vector<LoopClosure> LoopClosures() const { return {}; }
  /// The loop-closure candidates it matched and rejected (a failed match or check), for the
  /// recording; default none.
  virtual std::vector<LoopClosure> RejectedLoopClosures() const { return {}; }
  /// The landmark map and the sightings behind it (landmark estimators); default none.
  virtual LandmarkMap Landmarks() const { return {}; }
  /// Extras for the live view.
  virtual EstimatorView View() const { return {}; }
};

}  // namespace slamrig::slam
