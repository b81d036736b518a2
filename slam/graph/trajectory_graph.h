#pragma once

#include <Eigen/Core>

#include "slam/graph/pose_graph.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// A pose graph of a trajectory, for users who want its poses as g2o VERTEX_SE2/EDGE_SE2 (e.g.
/// to hand a front end's output to another back end): vertex i at trajectory[i].pose (ids
/// 0..n-1, the first fixed) and an odometry edge i -> i+1 measuring the relative pose
/// trajectory[i]^-1 * trajectory[i+1] with `odometry_information` (3x3, symmetric positive
/// definite). Add loop closures or other relative-pose edges with
/// AddRelativePoseEdge, then write with WriteG2o.
PoseGraph PoseGraphFromTrajectory(const Trajectory& trajectory,
                                  const Eigen::Matrix3d& odometry_information);

/// Adds the edge `from` -> `to` that measures `from_T_to`, with `information` (SPD; checked by
/// PoseGraph::AddEdge).
/// Its kind is odometry when |to - from| = 1, a loop closure otherwise, as for g2o files.
void AddRelativePoseEdge(PoseGraph* graph, int from, int to, const Pose2& from_T_to,
                         const Eigen::Matrix3d& information);

}  // namespace slamrig::slam
