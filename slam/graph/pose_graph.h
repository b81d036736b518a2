#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <unordered_map>
#include <vector>

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// What produced an edge: consecutive-pose odometry, a loop closure, or anything else (a scan
/// match between nearby poses, a prior). Robust losses can be restricted to loop closures.
enum class EdgeKind { kOdometry, kLoopClosure, kOther };

/// One pose of the graph: `world_from_robot` at node `id`. A fixed vertex is never moved by the
/// optimiser (it anchors the gauge).
struct PoseGraphVertex {
  int id = 0;
  Pose2 pose;
  bool fixed = false;
};

/// A relative-pose measurement between two vertices: `measurement` (Z) is the pose of `to`
/// expressed in the frame of `from` (`from_T_to`), with `information` (Ω, 3x3 symmetric positive
/// definite, order x, y, theta) its inverse covariance, as in g2o's EDGE_SE2.
struct PoseGraphEdge {
  int from = 0;
  int to = 0;
  Pose2 measurement;
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
  EdgeKind kind = EdgeKind::kOther;
};

/// A 2D pose graph that grows online: a front end adds vertices and edges one at a time and
/// re-optimises (PoseGraphOptimizer) from the current poses as a warm start; files (g2o_io.h) fill
/// it in one go. Vertices keep the order they were added in; ids are any distinct integers.
class PoseGraph {
 public:
  /// Adds a vertex. `id` must be new (SLAMRIG_CHECK): callers check HasVertex() for input data.
  void AddVertex(int id, const Pose2& pose, bool fixed = false);
  /// Adds an edge. Both ends must exist and differ, and the information matrix must be
  /// symmetric positive definite (SLAMRIG_CHECK; the readers reject such input with a
  /// ParseError before it gets here).
  void AddEdge(const PoseGraphEdge& edge);
  /// Replaces the information matrix of edges()[k] (same SLAMRIG_CHECKs as AddEdge).
  void SetEdgeInformation(std::size_t k, const Eigen::Matrix3d& information);

  bool HasVertex(int id) const { return index_.count(id) != 0; }
  /// Index of vertex `id` in vertices() (SLAMRIG_CHECK that it exists).
  std::size_t IndexOf(int id) const;
  const PoseGraphVertex& vertex(int id) const { return vertices_[IndexOf(id)]; }
  /// The current estimate of vertex `id`.
  const Pose2& pose(int id) const { return vertex(id).pose; }
  void SetPose(int id, const Pose2& pose) { vertices_[IndexOf(id)].pose = pose; }
  void SetFixed(int id, bool fixed) { vertices_[IndexOf(id)].fixed = fixed; }

  /// All vertices in insertion order; vertices()[IndexOf(id)].id == id.
  const std::vector<PoseGraphVertex>& vertices() const { return vertices_; }
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  bool empty() const { return vertices_.empty(); }

  /// The indices the optimiser holds constant: the fixed vertices, or the first vertex when
  /// none is fixed (the gauge freedom of a relative-pose graph). Empty for an empty graph.
  std::vector<std::size_t> AnchorIndices() const;

 private:
  std::vector<PoseGraphVertex> vertices_;
  std::vector<PoseGraphEdge> edges_;
  std::unordered_map<int, std::size_t> index_;
};

}  // namespace slamrig::slam
