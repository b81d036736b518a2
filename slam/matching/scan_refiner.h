#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "slam/matching/grid_view.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// Gauss-Newton refinement of a scan pose on a smooth raster.
struct ScanRefinerOptions {
  int max_iterations = 6;
  double max_step_m = 0.05;        ///< a larger translation step is scaled down to this
  double max_step_rad = 0.02;      ///< a larger rotation step is scaled down to this
  double converged_step_m = 1e-4;  ///< stop when the step is smaller (and its rotation < 1e-4 rad)
  /// Gaussian prior on the pose around a given mean (Cartographer's Ceres scan matcher's
  /// translation and rotation weights): the refiner maximises score - 0.5 (|d_xy| /
  /// prior_sigma_xy_m)^2 - 0.5 (d_yaw / prior_sigma_yaw_rad)^2 (score units) and the prior enters
  /// the normal equations, so a flat direction (a corridor) is pulled back to the mean instead of
  /// drifting. 0 = no prior on that part.
  double prior_sigma_xy_m = 0.0;
  double prior_sigma_yaw_rad = 0.0;
  /// What the steps climb. false: Hector's Gauss-Newton on the residuals 1 - M, whose optimum
  /// weights the worst-fitting points most and is not the score's; a step that lowers the score
  /// ends the refinement, so it stops between the two optima at a point that depends on where it
  /// started. true: the score minus the prior itself, along the Gauss-Newton direction with the
  /// score's gradient (an ascent direction: the normal matrix is positive definite), each step
  /// halved up to max_halvings times until it raises the score; it ends near the score's maximum
  /// in the start's basin, wherever in the basin the start is. Off: on the pf it only reshuffles
  /// the seeds (README, "Particle filter: the map-writing pose").
  bool maximise_score = false;
  int max_halvings = 5;  ///< with maximise_score: step halvings tried before giving up

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of ScanRefinerOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, ScanRefinerOptions& o) {
  v("max_iterations", o.max_iterations);
  v("max_step_m", o.max_step_m);
  v("max_step_rad", o.max_step_rad);
  v("converged_step_m", o.converged_step_m);
  v("prior_sigma_xy_m", o.prior_sigma_xy_m);
  v("prior_sigma_yaw_rad", o.prior_sigma_yaw_rad);
  v("maximise_score", o.maximise_score);
  v("max_halvings", o.max_halvings);
}

/// A refined pose and its score.
struct RefineResult {
  Pose2 pose;
  double score = 0.0;       ///< sum over points of the bilinearly interpolated raster value
  double prior_cost = 0.0;  ///< the prior's penalty at `pose` (score units)
  int iterations = 0;
};

/// Sub-cell scan alignment: maximises the bilinearly interpolated raster values at the scan points
/// by Gauss-Newton on the residuals 1 - M(S(xi) p) with M the raster scaled to [0, 1]
/// (Kohlbrecher et al., "A Flexible and Scalable SLAM System with Full 3D Motion Estimation"
/// (Hector SLAM), SSRR 2011, Sec. IV-A, Eqs. 6-13), run on the likelihood field instead of the
/// occupancy probabilities. A step that lowers the score (minus the prior's cost) is not taken.
/// Thread-safe.
class ScanRefiner {
 public:
  explicit ScanRefiner(const ScanRefinerOptions& options);

  /// Refines `initial`; `max_value` is the raster's largest possible value (scales M to [0, 1]).
  /// The prior, if any, is centred on `initial`.
  RefineResult Refine(const GridView& raster, float max_value,
                      std::span<const Eigen::Vector2d> points_base, const Pose2& initial) const;

  /// As above with the prior centred on `prior_mean` (e.g. the predicted pose before a shift
  /// search moved it to `initial`).
  RefineResult Refine(const GridView& raster, float max_value,
                      std::span<const Eigen::Vector2d> points_base, const Pose2& initial,
                      const Pose2& prior_mean) const;

  /// Sum over points of the interpolated raster value at `pose`.
  static double Score(const GridView& raster, std::span<const Eigen::Vector2d> points_base,
                      const Pose2& pose);
  /// The interpolated raster value at a world point, as the refinement samples it.
  static double ValueAt(const GridView& raster, const Eigen::Vector2d& world);

 private:
  ScanRefinerOptions options_;
};

}  // namespace slamrig::slam
