#include "slam/graph/pose_graph.h"

#include <Eigen/Cholesky>

#include "slam/types/check.h"

namespace slamrig::slam {

void PoseGraph::AddVertex(int id, const Pose2& pose, bool fixed) {
  const bool inserted = index_.emplace(id, vertices_.size()).second;
  SLAMRIG_CHECK(inserted, "PoseGraph::AddVertex: duplicate vertex id");
  vertices_.push_back({.id = id, .pose = pose, .fixed = fixed});
}

namespace {

bool SymmetricPositiveDefinite(const Eigen::Matrix3d& m) {
  return m.allFinite() && m.isApprox(m.transpose()) &&
         Eigen::LLT<Eigen::Matrix3d>(m).info() == Eigen::Success;
}

}  // namespace

void PoseGraph::AddEdge(const PoseGraphEdge& edge) {
  SLAMRIG_CHECK(HasVertex(edge.from) && HasVertex(edge.to),
                "PoseGraph::AddEdge: edge to a vertex that was never added");
  SLAMRIG_CHECK(edge.from != edge.to, "PoseGraph::AddEdge: edge from a vertex to itself");
  SLAMRIG_CHECK(SymmetricPositiveDefinite(edge.information),
                "PoseGraph::AddEdge: information is not symmetric positive definite");
  edges_.push_back(edge);
}

void PoseGraph::SetEdgeInformation(std::size_t k, const Eigen::Matrix3d& information) {
  SLAMRIG_CHECK(k < edges_.size(), "PoseGraph::SetEdgeInformation: no such edge");
  SLAMRIG_CHECK(SymmetricPositiveDefinite(information),
                "PoseGraph::SetEdgeInformation: information is not symmetric positive definite");
  edges_[k].information = information;
}

std::size_t PoseGraph::IndexOf(int id) const {
  const auto it = index_.find(id);
  SLAMRIG_CHECK(it != index_.end(), "PoseGraph: unknown vertex id");
  return it->second;
}

std::vector<std::size_t> PoseGraph::AnchorIndices() const {
  std::vector<std::size_t> anchors;
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    if (vertices_[i].fixed) anchors.push_back(i);
  }
  if (anchors.empty() && !vertices_.empty()) anchors.push_back(0);
  return anchors;
}

}  // namespace slamrig::slam
