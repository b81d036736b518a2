#include "slam/graph/trajectory_graph.h"

namespace slamrig::slam {

void AddRelativePoseEdge(PoseGraph* graph, int from, int to, const Pose2& from_T_to,
                         const Eigen::Matrix3d& information) {
  const int gap = to - from;
  graph->AddEdge({.from = from,
                  .to = to,
                  .measurement = from_T_to,
                  .information = information,
                  .kind = (gap == 1 || gap == -1) ? EdgeKind::kOdometry : EdgeKind::kLoopClosure});
}

PoseGraph PoseGraphFromTrajectory(const Trajectory& trajectory,
                                  const Eigen::Matrix3d& odometry_information) {
  PoseGraph graph;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    graph.AddVertex(static_cast<int>(i), trajectory[i].pose, i == 0);
  }
  for (std::size_t i = 0; i + 1 < trajectory.size(); ++i) {
    AddRelativePoseEdge(&graph, static_cast<int>(i), static_cast<int>(i + 1),
                        trajectory[i].pose.Between(trajectory[i + 1].pose), odometry_information);
  }
  return graph;
}

}  // namespace slamrig::slam
