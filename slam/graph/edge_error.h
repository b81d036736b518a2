#pragma once

// The SE(2) relative-pose error of g2o's EDGE_SE2 (Kümmerle et al., "g2o: A general framework for
// graph optimization", ICRA 2011, eq. 1-2 with the SE(2) error of types_slam2d/edge_se2.h):
//   e_ij = t2v(Z_ij^-1 * (X_i^-1 * X_j)),   chi2 = sum_ij e_ij^T * Omega_ij * e_ij   (no 1/2),
// where t2v gives (x, y, theta) with theta wrapped into (-pi, pi].

#include <Eigen/Core>

#include "slam/graph/pose_graph.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The error e = t2v(Z^-1 * (Xi^-1 * Xj)) of measurement `z` between poses `xi` and `xj`, and
/// its Jacobians with respect to (x, y, theta) of each pose.
struct EdgeErrorResult {
  Eigen::Vector3d error;
  Eigen::Matrix3d d_error_d_xi;
  Eigen::Matrix3d d_error_d_xj;
};

/// Evaluates e and its analytic Jacobians; xi and xj are given as (x, y, theta).
EdgeErrorResult EvaluateEdgeError(const Eigen::Vector3d& xi, const Eigen::Vector3d& xj,
                                  const Pose2& z);

/// The error of `edge` at the graph's current poses.
Eigen::Vector3d EdgeError(const PoseGraph& graph, const PoseGraphEdge& edge);

/// e^T Omega e of `edge` at the graph's current poses.
double EdgeChi2(const PoseGraph& graph, const PoseGraphEdge& edge);

/// The 99 % quantile of chi2 with 3 degrees of freedom: an edge above it is strained.
inline constexpr double kEdgeChi2P99 = 11.3449;

/// g2o's chi2 of the whole graph at its current poses: sum of e^T Omega e over all edges.
double Chi2(const PoseGraph& graph);

}  // namespace slamrig::slam
