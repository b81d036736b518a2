#include "slam/graph/graph_initialization.h"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <utility>
#include <vector>

#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// Sparse linear least squares over 2-vectors: the sum over terms of |J_a x_a + J_b x_b - r|^2_W,
// where some x are known (their columns move to the right-hand side r).
class BlockLeastSquares {
 public:
  // `unknown[i]` is the unknown's index of vertex i, or -1 when vertex i is known = known[i].
  BlockLeastSquares(std::vector<Eigen::Index> unknown, std::vector<Eigen::Vector2d> known,
                    Eigen::Index num_unknowns)
      : unknown_(std::move(unknown)), known_(std::move(known)), g_(2 * num_unknowns) {
    g_.setZero();
  }

  void Add(std::size_t a, const Eigen::Matrix2d& j_a, std::size_t b, const Eigen::Matrix2d& j_b,
           Eigen::Vector2d rhs, const Eigen::Matrix2d& w) {
    const Eigen::Index ua = unknown_[a], ub = unknown_[b];
    if (ua < 0) rhs -= j_a * known_[a];
    if (ub < 0) rhs -= j_b * known_[b];
    const std::pair<Eigen::Index, const Eigen::Matrix2d*> blocks[] = {{ua, &j_a}, {ub, &j_b}};
    for (const auto& [r, j_r] : blocks) {
      if (r < 0) continue;
      g_.segment<2>(2 * r) += j_r->transpose() * w * rhs;
      for (const auto& [c, j_c] : blocks) {
        if (c < 0) continue;
        const Eigen::Matrix2d h = j_r->transpose() * w * *j_c;
        for (int k = 0; k < 2; ++k) {
          for (int l = 0; l < 2; ++l) triplets_.emplace_back(2 * r + k, 2 * c + l, h(k, l));
        }
      }
    }
  }

  // The minimiser, or an empty vector when the normal equations are singular.
  Eigen::VectorXd Solve() const {
    Eigen::SparseMatrix<double> h(g_.size(), g_.size());
    h.setFromTriplets(triplets_.begin(), triplets_.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(h);
    if (ldlt.info() != Eigen::Success) return {};
    return ldlt.solve(g_);
  }

 private:
  std::vector<Eigen::Index> unknown_;
  std::vector<Eigen::Vector2d> known_;
  Eigen::VectorXd g_;
  std::vector<Eigen::Triplet<double>> triplets_;
};

// Vertices reachable from an anchor through edges (either direction).
std::vector<bool> ReachableFromAnchors(const PoseGraph& graph) {
  const std::size_t n = graph.vertices().size();
  std::vector<std::vector<std::size_t>> neighbours(n);
  for (const PoseGraphEdge& e : graph.edges()) {
    const std::size_t a = graph.IndexOf(e.from), b = graph.IndexOf(e.to);
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  std::vector<bool> reached(n, false);
  std::deque<std::size_t> queue;
  for (const std::size_t a : graph.AnchorIndices()) {
    reached[a] = true;
    queue.push_back(a);
  }
  while (!queue.empty()) {
    const std::size_t v = queue.front();
    queue.pop_front();
    for (const std::size_t w : neighbours[v]) {
      if (!reached[w]) {
        reached[w] = true;
        queue.push_back(w);
      }
    }
  }
  return reached;
}

}  // namespace

InitializationSummary InitializeFromOdometry(PoseGraph* graph) {
  InitializationSummary summary;
  const auto& vertices = graph->vertices();
  const std::size_t n = vertices.size();
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return vertices[a].id < vertices[b].id; });
  std::vector<std::size_t> rank(n);
  for (std::size_t k = 0; k < n; ++k) rank[order[k]] = k;
  // chain[k]: the first edge between the k-th and (k+1)-th ids, either direction.
  std::vector<const PoseGraphEdge*> chain(n, nullptr);
  for (const PoseGraphEdge& e : graph->edges()) {
    const std::size_t ra = rank[graph->IndexOf(e.from)], rb = rank[graph->IndexOf(e.to)];
    const std::size_t low = std::min(ra, rb);
    if (std::max(ra, rb) == low + 1 && chain[low] == nullptr) chain[low] = &e;
  }
  const std::vector<PoseGraphVertex> before = vertices;  // for the gaps of the chain
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const PoseGraphVertex& prev = vertices[order[k]];
    const PoseGraphVertex& next = vertices[order[k + 1]];
    if (next.fixed) continue;
    Pose2 prev_from_next;
    if (chain[k] == nullptr) {
      prev_from_next = before[order[k]].pose.Between(before[order[k + 1]].pose);
      ++summary.vertices_kept;
    } else {
      prev_from_next =
          chain[k]->from == prev.id ? chain[k]->measurement : chain[k]->measurement.Inverse();
      ++summary.vertices_set;
    }
    graph->SetPose(next.id, prev.pose * prev_from_next);
  }
  return summary;
}

InitializationSummary InitializeChordal(PoseGraph* graph) {
  InitializationSummary summary;
  const auto& vertices = graph->vertices();
  const std::size_t n = vertices.size();
  const std::vector<bool> reached = ReachableFromAnchors(*graph);
  std::vector<bool> anchor(n, false);
  for (const std::size_t a : graph->AnchorIndices()) anchor[a] = true;
  std::vector<Eigen::Index> unknown(n, -1);
  Eigen::Index num_unknowns = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (reached[i] && !anchor[i]) unknown[i] = num_unknowns++;
    if (!reached[i]) ++summary.vertices_kept;
  }
  if (num_unknowns == 0) return summary;

  // (1) Rotations as (cos, sin): [c_j, s_j] = R(theta_ij) [c_i, s_i] for each edge.
  std::vector<Eigen::Vector2d> known(n, Eigen::Vector2d::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    known[i] = {std::cos(vertices[i].pose.theta()), std::sin(vertices[i].pose.theta())};
  }
  BlockLeastSquares rotations(unknown, known, num_unknowns);
  for (const PoseGraphEdge& e : graph->edges()) {
    const std::size_t a = graph->IndexOf(e.from), b = graph->IndexOf(e.to);
    if (!reached[a]) continue;
    const double rotation_information = 1.0 / e.information.inverse()(2, 2);
    rotations.Add(a, -RotationMatrix(e.measurement.theta()), b, Eigen::Matrix2d::Identity(),
                  Eigen::Vector2d::Zero(), rotation_information * Eigen::Matrix2d::Identity());
  }
  const Eigen::VectorXd cs = rotations.Solve();
  SLAMRIG_CHECK(cs.size() == 2 * num_unknowns, "chordal rotations: singular normal equations");

  // (2) Projection to SO(2).
  std::vector<double> theta(n);
  for (std::size_t i = 0; i < n; ++i) {
    theta[i] = unknown[i] < 0 ? vertices[i].pose.theta()
                              : std::atan2(cs(2 * unknown[i] + 1), cs(2 * unknown[i]));
  }

  // (3) Translations with the rotations fixed: R_i^T (t_j - t_i) = t_ij.
  for (std::size_t i = 0; i < n; ++i) known[i] = vertices[i].pose.translation();
  BlockLeastSquares translations(unknown, known, num_unknowns);
  for (const PoseGraphEdge& e : graph->edges()) {
    const std::size_t a = graph->IndexOf(e.from), b = graph->IndexOf(e.to);
    if (!reached[a]) continue;
    const Eigen::Matrix2d rt = RotationMatrix(theta[a]).transpose();
    translations.Add(a, -rt, b, rt, e.measurement.translation(),
                     e.information.topLeftCorner<2, 2>());
  }
  const Eigen::VectorXd t = translations.Solve();
  SLAMRIG_CHECK(t.size() == 2 * num_unknowns, "chordal translations: singular normal equations");

  for (std::size_t i = 0; i < n; ++i) {
    if (unknown[i] < 0) continue;
    graph->SetPose(vertices[i].id, Pose2(t(2 * unknown[i]), t(2 * unknown[i] + 1), theta[i]));
    ++summary.vertices_set;
  }
  return summary;
}

}  // namespace slamrig::slam
