#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/fusion/ekf_slam.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/health.h"
#include "slam/pipeline/wheel_gyro_feed.h"

namespace slamrig::slam {

/// Options of the `ekf-slam` estimator: the filter's, and the map drawn along its poses.
struct EkfSlamEstimatorOptions {
  EkfSlamOptions filter;  ///< its keys sit at this level
  OccupancyGridOptions map;
  /// Every this many scans one is drawn into the occupancy map (the landmarks are the SLAM map;
  /// the grid is for the picture and the map scores, and tracing every beam of every scan costs
  /// more than the filter).
  int map_every_scans = 4;

  /// One message per broken rule, named by the YAML keys.
  std::vector<std::string> Validate() const;
};

/// The field table of EkfSlamEstimatorOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, EkfSlamEstimatorOptions& o) {
  VisitFields(v, o.filter);
  v.Struct("map", o.map);
  v("map_every_scans", o.map_every_scans);
}

/// Landmark EKF-SLAM (EkfSlam): wheel encoders and the gyro predict as their records arrive
/// (odometry-pose increments at the scans when the source has no encoders), gyro samples at
/// standstill measure the bias, and each scan's round landmarks (ExtractLandmarks) update the
/// pose and the landmark map. The occupancy map is the scans drawn at the online poses. Reports
/// the pose covariance with every pose, and the landmarks with their covariances.
class EkfSlamEstimator final : public Estimator {
 public:
  EkfSlamEstimator(const EkfSlamEstimatorOptions& options, const EstimatorContext& context);

  void AddRecord(const Record& record) override;
  ScanEstimate AddScan(const SyncedScan& scan) override;
  const OccupancyGrid& map() const override { return map_; }
  std::map<std::string, double> Statistics() const override;
  /// The names Statistics() reports, without an instance: the algorithm table's list (and so
  /// the expectations'); EstimatorRunner checks every run's Statistics() against it.
  static const std::vector<std::string>& StatisticNames();
  LandmarkMap Landmarks() const override;
  EstimatorView View() const override;

 private:
  std::vector<LandmarkEstimate> CurrentLandmarks() const;

  EkfSlamEstimatorOptions options_;
  WheelGyroFeed<EkfSlam> feed_;
  EkfSlam slam_;
  OccupancyGrid map_;
  std::vector<LandmarkSighting> sightings_;
  int scans_ = 0;
  int observations_ = 0;
  int pairings_ = 0;
  int ambiguous_ = 0;
  int updates_ = 0;
  double nis_sum_ = 0.0;
  double nis_dof_sum_ = 0.0;
  NisWindow nis_window_;
  HealthRecord health_;
};

}  // namespace slamrig::slam
