#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/odometry/scan_sync.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/estimator_config.h"
#include "slam/pipeline/health.h"
#include "slam/pipeline/scan_matched_odometry.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// What one estimator produced over a run, in its own frame (base_link at its first scan).
struct EstimatorRun {
  std::string name;       ///< the configuration's name
  std::string algorithm;  ///< its algorithm
  Trajectory online;      ///< the pose reported at each scan, stamped with the scan's own time
  Trajectory final;       ///< revised where the estimator revises its past, else `online`
  Trajectory mean;        ///< the second estimate at each scan (a PF's mean), else empty
  /// The online pose's covariance at each scan (estimator frame), when the estimator gives one
  /// for every scan; else empty.
  std::vector<Eigen::Matrix3d> covariances;
  /// Estimator::RecordEstimate() after every record that gave one, at the record's time, and
  /// the covariances when every one had one; empty for estimators that only report at scans.
  Trajectory record_rate;
  std::vector<Eigen::Matrix3d> record_rate_covariances;
  std::vector<double> trace_time_s;                   ///< scan times of the traces, seconds
  std::map<std::string, std::vector<double>> traces;  ///< per-scan values by name
  std::map<std::string, double> statistics;           ///< Estimator::Statistics() at the end
  /// Whether the estimator judged every scan (ScanEstimate::lost), and its runs of lost scans.
  bool judges_itself = false;
  std::vector<LostInterval> lost_intervals;
  std::vector<LoopClosure> loop_closures;                  ///< Estimator::LoopClosures() at the end
  std::vector<LoopClosure> rejected_loop_closures;         ///< Estimator::RejectedLoopClosures()
  LandmarkMap landmarks;                                   ///< Estimator::Landmarks() at the end
  OccupancyGrid map{OccupancyGridOptions{}};               ///< the final map
  OdometrySource odometry_source = OdometrySource::kNone;  ///< the odometry used
  int gyro_fallbacks = 0;          ///< intervals without IMU samples (ScanSynchronizer)
  int scans_without_odometry = 0;  ///< scans before any odometry
  /// Without odometry (source none): how the scan-matched motion prior placed the scans.
  std::optional<IcpOdometryCounts> scan_matched_odometry;
  double wall_s = 0.0;  ///< wall time spent in sync and estimator (the only wall-clock figure)
};

/// Feeds records, one at a time, through a ScanSynchronizer into one Estimator, and keeps what
/// the estimator reports: the streaming form that the scenario runner (a simulator on the same
/// clock) and RunEstimator (a whole log) share, so that both give the same bits.
class EstimatorRunner {
 public:
  /// `source` must be resolved (ResolveOdometrySource); `run_seed` seeds the estimator's stream.
  EstimatorRunner(const EstimatorConfig& config, OdometrySource source, std::uint64_t run_seed);

  /// The next record; scans it completes go to the estimator at once.
  void Add(const Record& record);
  /// The end of the data: the scans still waiting for odometry, then Estimator::Finish().
  void Finish();

  /// Called after each scan the estimator took (index from 0, the synced scan, its estimate).
  void SetScanCallback(std::function<void(std::size_t, const SyncedScan&, const ScanEstimate&)> f) {
    on_scan_ = std::move(f);
  }

  const EstimatorConfig& config() const { return config_; }
  const Estimator& estimator() const { return *estimator_; }
  /// The estimator, for what a caller attaches to it before the first record (an external
  /// estimator's stream).
  Estimator& estimator() { return *estimator_; }
  /// Scans the estimator has taken so far.
  std::size_t scans() const { return run_.online.size(); }
  /// The last online pose (identity before the first scan).
  const Pose2& pose() const { return pose_; }

  /// The run's results; call once, after Finish().
  EstimatorRun TakeResult();

 private:
  void Process(const SyncedScan& scan);

  EstimatorConfig config_;
  ScanSynchronizer sync_;
  /// The motion prior of a source without odometry (ScanMatchedOdometry), else empty.
  std::optional<ScanMatchedOdometry> scan_odometry_;
  std::unique_ptr<Estimator> estimator_;
  std::function<void(std::size_t, const SyncedScan&, const ScanEstimate&)> on_scan_;
  EstimatorRun run_;
  std::vector<bool> lost_;  // ScanEstimate::lost of each scan (false where it had none)
  int judged_scans_ = 0;    // scans that had one
  Pose2 pose_;
  bool finished_ = false;
};

/// Limits of a batch run.
struct RunLimits {
  std::size_t max_scans = 0;  ///< stop after this many scans (0: all)
};

/// Runs `config` over a whole record list (a log): EstimatorRunner over every record, so a log
/// and a live source give identical results. `odometry.robot` of the config must fit the log.
/// `on_scan` (optional) sees every scan as the runner's callback does.
EstimatorRun RunEstimator(
    const EstimatorConfig& config, const std::vector<Record>& records, std::uint64_t run_seed,
    const RunLimits& limits = {},
    std::function<void(std::size_t, const SyncedScan&, const ScanEstimate&)> on_scan = nullptr);

}  // namespace slamrig::slam
