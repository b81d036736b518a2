// The algorithm table: the one place that lists the estimators. Adding an algorithm is one entry
// here plus its Estimator; every command, sweep, view and report then runs it.

#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/dead_reckoning_estimator.h"
#include "slam/pipeline/ekf_estimator.h"
#include "slam/pipeline/ekf_slam_estimator.h"
#include "slam/pipeline/external_estimator.h"
#include "slam/pipeline/graph_slam_estimator.h"
#include "slam/pipeline/icp_odometry_estimator.h"
#include "slam/pipeline/particle_filter_estimator.h"
#include "slam/pipeline/python_estimator.h"
#include "slam/pipeline/rbpf_estimator.h"

namespace slamrig::slam {

const std::vector<Algorithm>& Algorithms() {
  static const std::vector<Algorithm> algorithms = {
      {"dead-reckoning",
       "odometry alone, the map built along it",
       {"default"},
       {},
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<AlgorithmOptionsFor<DeadReckoningOptions, DeadReckoningEstimator>>(
             DeadReckoningOptions{});
       }},
      {"pf",
       "particle-filter SLAM on one log-odds map (presets: default, the improved filter; "
       "reports, the ECE276A reports' method)",
       {"default", "reports"},
       ParticleFilterEstimator::StatisticNames(),
       [](const std::string& preset) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<
             AlgorithmOptionsFor<ParticleFilterOptions, ParticleFilterEstimator>>(
             preset == "reports" ? ParticleFilterOptions::ReportsPreset()
                                 : ParticleFilterOptions{});
       }},
      {"ekf",
       "EKF pose fusion: encoders and gyro predict, scan-to-local-map ICP matches correct, "
       "the gyro bias estimated; a covariance with every pose",
       {"default"},
       EkfEstimator::StatisticNames(),
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<AlgorithmOptionsFor<EkfOptions, EkfEstimator>>(EkfOptions{});
       }},
      {"ekf-slam",
       "landmark EKF-SLAM: encoders and gyro predict, round landmarks (pillars) from each scan "
       "update pose and map, association by nearest neighbour or JCBB",
       {"default"},
       EkfSlamEstimator::StatisticNames(),
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<AlgorithmOptionsFor<EkfSlamEstimatorOptions, EkfSlamEstimator>>(
             EkfSlamEstimatorOptions{});
       },
       /*maps_landmarks=*/true},
      {"icp-odometry",
       "scan-to-local-map point-to-line ICP with the wheel odometry as prior, the map along it",
       {"default"},
       IcpOdometryEstimator::StatisticNames(),
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<
             AlgorithmOptionsFor<IcpOdometryEstimatorOptions, IcpOdometryEstimator>>(
             IcpOdometryEstimatorOptions{});
       }},
      {"graph",
       "graph SLAM: ICP odometry keyframes, loop closures by correlative matching verified by "
       "ICP and a chi2 gate, Ceres with a robust loss",
       {"default"},
       GraphSlamEstimator::StatisticNames(),
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<
             AlgorithmOptionsFor<GraphSlamEstimatorOptions, GraphSlamEstimator>>(
             GraphSlamEstimatorOptions{});
       },
       /*maps_landmarks=*/false,
       /*closes_loops=*/true},
      {"rbpf",
       "Rao-Blackwellised particle filter with per-particle copy-on-write maps (GMapping's "
       "scan-matched proposal, selective resampling); revises its past",
       {"default"},
       RbpfEstimator::StatisticNames(),
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<AlgorithmOptionsFor<RbpfOptions, RbpfEstimator>>(RbpfOptions{});
       }},
      {"python",
       "an estimator written in Python: `module:` and `class:` (found beside the scenario, then "
       "on PYTHONPATH), every other key passed to the class as a keyword",
       {"default"},
       {},
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<PythonAlgorithmOptions>();
       },
       /*maps_landmarks=*/false,
       /*closes_loops=*/true,
       /*statistics_declared=*/false,
       /*runs_beside_others=*/false},
      {"external",
       "any program as an estimator: `command:` (no shell; {input}, {output}, {seed} replaced) "
       "reads the records as `input:` (carmen, mcap, sqlite3, ece276a) and writes a TUM "
       "trajectory, and a map_server map beside it if it has one (docs/external.md)",
       {"default"},
       ExternalEstimator::StatisticNames(),
       [](const std::string&) -> std::unique_ptr<AlgorithmOptions> {
         return std::make_unique<ExternalAlgorithmOptions>();
       },
       /*maps_landmarks=*/false,
       /*closes_loops=*/false,
       // The scenario runner adds them after the program ends; the in-process part has none.
       /*statistics_declared=*/false,
       /*runs_beside_others=*/false},
  };
  return algorithms;
}

const Algorithm* FindAlgorithm(const std::string& name) {
  for (const Algorithm& a : Algorithms()) {
    if (a.name == name) return &a;
  }
  return nullptr;
}

std::string AlgorithmNames() {
  std::string names;
  for (const Algorithm& a : Algorithms()) names += (names.empty() ? "" : ", ") + a.name;
  return names;
}

}  // namespace slamrig::slam
