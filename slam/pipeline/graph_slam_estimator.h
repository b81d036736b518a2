#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/graph/graph_slam.h"
#include "slam/graph/graph_slam_options.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/pipeline/algorithm.h"
#include "slam/pipeline/estimator.h"
#include "slam/pipeline/health.h"
#include "slam/pipeline/revisits.h"

namespace slamrig::slam {

/// Options of the `graph` algorithm: GraphSlam's and the map's.
struct GraphSlamEstimatorOptions {
  GraphSlamOptions graph;
  OccupancyGridOptions map;

  /// One message per broken rule ("loop_chi2_gate = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

/// The field table of GraphSlamEstimatorOptions: GraphSlam's keys at the top level.
template <typename V>
void VisitFields(V& v, GraphSlamEstimatorOptions& o) {
  VisitFields(v, o.graph);
  v.Struct("map", o.map);
}

/// Graph SLAM with verified loop closures (GraphSlam) behind the Estimator interface. The map
/// holds the scans of the graph's nodes (keyframes), online at their online poses; Finish()
/// optimises once more and rebuilds it from the nodes' revised poses.
class GraphSlamEstimator final : public Estimator {
 public:
  GraphSlamEstimator(const GraphSlamEstimatorOptions& options, const EstimatorContext& context);

  ScanEstimate AddScan(const SyncedScan& scan) override;
  void Finish() override;
  std::optional<std::vector<Pose2>> RevisedPoses() const override { return slam_.Poses(); }
  const OccupancyGrid& map() const override { return map_; }
  /// keyframes, loop_closures, loop_candidates, rejected, optimizations, final_chi2,
  /// switched_off, odometry_rematched, window_edge_rejected, gate_rejected, inconsistent, the
  /// certificate's, and its own judgement: strained_edges, chi2_ratio, unrepaired_losses,
  /// unrepaired_error_bound_m, wheel_heading_contradiction_rad, wheel_heading_noise_scale, lost,
  /// diverged.
  std::map<std::string, double> Statistics() const override;
  /// The names Statistics() reports, without an instance: the algorithm table's list (and so
  /// the expectations'); EstimatorRunner checks every run's Statistics() against it.
  static const std::vector<std::string>& StatisticNames();
  std::vector<LoopClosure> LoopClosures() const override { return slam_.loop_closures(); }
  std::vector<LoopClosure> RejectedLoopClosures() const override {
    return slam_.rejected_closures();
  }
  /// The graph's odometry and loop-closure edges at the current estimate.
  EstimatorView View() const override;
  /// After Finish(): the front end's losses that no loop closure the final poses agree with
  /// spans (from a scan before the loss to one after it). A lost scan is placed by the odometry
  /// alone; only such a closure measures, and so corrects, the error it left in the estimate.
  int UnrepairedLosses() const;
  /// After Finish(): for each unrepaired loss, the 99 % bound on the position error its
  /// odometry-only stretch may have left (BlindStretchBound with the front end's odometry noise
  /// model). The run is diverged when one exceeds kDivergedErrorM; how many scans were lost is
  /// not the verdict: a loss a closure repaired left no error, and one that none did is judged
  /// by what it may have left.
  std::vector<double> UnrepairedLossBounds() const;
  /// After Finish(): how far the final trajectory turned away from the wheels, beyond what their
  /// drift, skid and noise explain (WheelAgreement's turn test on the final poses; the wheels'
  /// heading noise is the front end's model scaled by the median of the final turns' residuals
  /// against them), rad; 0: never, or no own odometry. Above 0 the run is diverged: a wrong turn
  /// that no loop closure took back (a corridor matched at the wrong heading where the scans saw
  /// nothing else) leaves the map rotated from there on, each part consistent in itself.
  double WheelHeadingContradiction() const { return wheel_heading_contradiction_rad_; }

 private:
  // The final poses' turns against the wheels' (WheelHeadingContradiction), at Finish().
  void JudgeTurnsAgainstWheels();

  GraphSlamEstimatorOptions options_;
  GraphSlam slam_;
  OccupancyGrid map_;
  std::vector<LaserScan> node_scans_;  // the scan of each graph node (vertex id), for the map
  FrontEndHealth front_end_health_;
  HealthRecord health_;                  // its loss_scans() are the repair test's
  BlindStretchBound blind_;              // over the current loss
  std::vector<double> loss_bounds_m_;    // per loss (health_.loss_scans()), its bound at its end
  bool own_odometry_;                    // the wheels are a witness of the turns
  std::vector<Pose2> wheel_increments_;  // per scan, the wheels' increment since the previous one
  std::vector<bool> odometry_gaps_;      // per scan, the odometry was silent before it
  double wheel_heading_contradiction_rad_ = 0.0;
  double wheel_heading_noise_scale_ = 1.0;  // that median scale
  RevisitAgreement revisits_;               // the final map against itself, at Finish()
};

}  // namespace slamrig::slam
