#pragma once

#include <string>
#include <vector>

namespace slamrig::slam {

/// A robust loss on an edge's whitened squared error s = e^T Omega e (Ceres's LossFunction):
/// none keeps the plain chi2, huber is quadratic up to s = scale^2 and linear in sqrt(s) beyond,
/// cauchy is scale^2 * log(1 + s / scale^2). switchable gives each robust edge a switch
/// w in [0, 1] that the solve estimates with the poses (Sünderhauf and Protzel, "Switchable
/// constraints for robust pose graph SLAM", IROS 2012, eq. 4, with the linear switch function):
/// the edge costs w^2 s + scale^2 (1 - w)^2, so at the optimum w = scale^2 / (s + scale^2), half
/// switched off where sqrt(s) = scale.
enum class RobustLoss { kNone, kHuber, kCauchy, kSwitchable };

/// The trust-region strategy of the Ceres solve.
enum class TrustRegion { kLevenbergMarquardt, kDogleg };

/// Options of PoseGraphOptimizer. Defaults reach the certified optima of the standard 2D
/// benchmarks (intel, city10000, ...) from a good initial guess; threads = 1 gives the same
/// bits on every run.
struct PoseGraphOptimizerOptions {
  /// Upper bound on Ceres iterations (successful or not). ais2klinik from odometry needs ~100.
  int max_iterations = 200;
  TrustRegion trust_region = TrustRegion::kLevenbergMarquardt;
  /// Initial trust-region radius (Ceres's; Levenberg-Marquardt's damping is its inverse). Large
  /// starts as Gauss-Newton, which converges in 3-7 iterations on the benchmark graphs where
  /// Ceres's default 1e4 takes 10-30; a failed step shrinks it as usual.
  double initial_trust_region_radius = 1e12;
  RobustLoss robust_loss = RobustLoss::kNone;
  /// Scale of the robust loss, in units of sqrt(chi2) of one edge (whitened error norm).
  double robust_loss_scale = 1.0;
  /// Apply the robust loss to every edge instead of loop closures only.
  bool robust_loss_on_all_edges = false;
  /// Differentiate the residual with Ceres's automatic differentiation instead of the analytic
  /// Jacobians (edge_error.h): same optimum, slower; for cross-checks and benchmarks.
  bool autodiff_jacobians = false;
  /// Ceres threads for evaluation and linear algebra. 1 keeps results bit-identical.
  int num_threads = 1;
  /// Stop when the relative decrease of the cost falls below this (Ceres function_tolerance).
  double function_tolerance = 1e-9;
  /// Stop when the max-norm of the projected gradient falls below this.
  double gradient_tolerance = 1e-10;
  /// Stop when the relative step size falls below this.
  double parameter_tolerance = 1e-9;

  /// One RuleViolation() message per broken rule; empty when the options are usable.
  std::vector<std::string> Validate() const;
};

/// "none", "huber" or "cauchy".
const char* RobustLossName(RobustLoss loss);
/// "levenberg_marquardt" or "dogleg".
const char* TrustRegionName(TrustRegion strategy);

}  // namespace slamrig::slam
