#pragma once

// Least-squares pose-graph optimisation with Ceres: minimises F(x) = sum e_ij^T Omega_ij e_ij
// (Kümmerle et al., "g2o: A general framework for graph optimization", ICRA 2011, eq. 1-2; the
// error in edge_error.h), each edge's error whitened by the Cholesky factor of its information
// matrix, poses on R^2 x SO(2) (the angle wrapped after every step), sparse Cholesky on the
// normal equations.

#include <string>
#include <vector>

#include "slam/graph/pose_graph.h"
#include "slam/graph/pose_graph_optimizer_options.h"

namespace slamrig::slam {

/// What one optimisation did. A solve that stops on max_iterations or a numerical failure is
/// reported here (converged = false, message says why), never thrown.
struct PoseGraphSummary {
  int num_vertices = 0;
  int num_edges = 0;
  /// g2o chi2 (sum e^T Omega e, no robust loss) before and after.
  double initial_chi2 = 0.0;
  double final_chi2 = 0.0;
  /// Ceres iterations taken (successful and unsuccessful steps).
  int iterations = 0;
  /// Wall time of the Ceres solve in seconds (a measurement only; it never steers the solve).
  double time_s = 0.0;
  /// True when a Ceres tolerance was met (not max_iterations, not a failure).
  bool converged = false;
  /// Ceres's termination message.
  std::string message;
  /// With RobustLoss::kSwitchable: the final switch of each edge, in PoseGraph::edges() order
  /// (1 for an edge without a switch); empty with the other losses.
  std::vector<double> switches;
};

/// Optimises a PoseGraph in place. Stateless between calls, so a front end that adds vertices
/// and edges and calls Optimize() again gets a warm start from the poses it left behind.
class PoseGraphOptimizer {
 public:
  /// SLAMRIG_CHECKs that options.Validate() is empty (callers validate user input first).
  explicit PoseGraphOptimizer(const PoseGraphOptimizerOptions& options);

  /// Moves every vertex except the anchors (PoseGraph::AnchorIndices()) to minimise chi2,
  /// starting from the graph's current poses, and writes the result back into `graph`.
  PoseGraphSummary Optimize(PoseGraph* graph) const;

  const PoseGraphOptimizerOptions& options() const { return options_; }

 private:
  PoseGraphOptimizerOptions options_;
};

}  // namespace slamrig::slam
