#include "slam/graph/pairwise_consistency.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// The larger eigenvalue of the xy block: an isotropic bound on the position variance, so that
// the frames the pieces of a cycle are expressed in do not matter.
double IsotropicXy(const Eigen::Matrix3d& covariance) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(covariance.topLeftCorner<2, 2>())
      .eigenvalues()[1];
}

}  // namespace

OdometryChain::OdometryChain()
    : poses_{Pose2()}, xy_{0.0}, yaw_{0.0}, yaw_p_{Eigen::Vector2d::Zero()}, yaw_p2_{0.0} {}

void OdometryChain::Append(const Pose2& relative, double variance_xy, double variance_yaw) {
  SLAMRIG_CHECK(variance_xy >= 0.0 && variance_yaw >= 0.0, "negative odometry variance");
  poses_.push_back(poses_.back() * relative);
  const Eigen::Vector2d p = poses_.back().translation();
  xy_.push_back(xy_.back() + variance_xy);
  yaw_.push_back(yaw_.back() + variance_yaw);
  yaw_p_.push_back(yaw_p_.back() + variance_yaw * p);
  yaw_p2_.push_back(yaw_p2_.back() + variance_yaw * p.squaredNorm());
}

Eigen::Vector2d OdometryChain::StretchVariance(int a, int b,
                                               const Eigen::Vector2d& lever_end) const {
  SLAMRIG_CHECK(a >= 0 && b >= 0 && a < size() && b < size(), "node outside the chain");
  const auto lo = static_cast<std::size_t>(std::min(a, b));
  const auto hi = static_cast<std::size_t>(std::max(a, b));
  const double s0 = yaw_[hi] - yaw_[lo];
  const Eigen::Vector2d s1 = yaw_p_[hi] - yaw_p_[lo];
  const double s2 = yaw_p2_[hi] - yaw_p2_[lo];
  // sum_k var_yaw_k |p_k - e|^2 = s2 - 2 e.s1 + |e|^2 s0.
  const double lever = std::max(0.0, s2 - 2.0 * lever_end.dot(s1) + lever_end.squaredNorm() * s0);
  return {xy_[hi] - xy_[lo] + lever, s0};
}

double PairwiseCycleChi2(const ClosureHypothesis& a, const ClosureHypothesis& b,
                         const OdometryChain& chain) {
  // The cycle in i_a's frame; it should compose to the identity.
  const Pose2 ja_to_jb = chain.pose(a.to).Between(chain.pose(b.to));
  const Pose2 ib_to_ia = chain.pose(b.from).Between(chain.pose(a.from));
  const Pose2 cycle = a.measurement * ja_to_jb * b.measurement.Inverse() * ib_to_ia;

  // Each piece's position variance, with its heading variance times the lever from the point
  // it pivots about to the cycle's end (i_a).
  double var_xy = 0.0;
  double var_yaw = 0.0;
  // Z_a pivots about j_a, which lies at Z_a's translation from i_a.
  var_xy +=
      IsotropicXy(a.covariance) + a.covariance(2, 2) * a.measurement.translation().squaredNorm();
  var_yaw += a.covariance(2, 2);
  // The j-side chain, with i_a placed on that side of it through Z_a.
  const Eigen::Vector2d ia_seen_from_j = (chain.pose(a.to) * a.measurement.Inverse()).translation();
  const Eigen::Vector2d j_side = chain.StretchVariance(a.to, b.to, ia_seen_from_j);
  var_xy += j_side.x();
  var_yaw += j_side.y();
  // Z_b^-1: inverting rotates its translation error by its heading error; it pivots about i_b.
  const double lever_ib =
      (chain.pose(b.from).translation() - chain.pose(a.from).translation()).squaredNorm();
  var_xy += IsotropicXy(b.covariance) +
            b.covariance(2, 2) * (b.measurement.translation().squaredNorm() + lever_ib);
  var_yaw += b.covariance(2, 2);
  // The i-side chain ends at i_a.
  const Eigen::Vector2d i_side =
      chain.StretchVariance(b.from, a.from, chain.pose(a.from).translation());
  var_xy += i_side.x();
  var_yaw += i_side.y();

  return cycle.translation().squaredNorm() / var_xy + cycle.theta() * cycle.theta() / var_yaw;
}

bool PairwiseConsistency::Add(const ClosureHypothesis& hypothesis, const OdometryChain& chain) {
  const int n = size();
  std::vector<bool> row(static_cast<std::size_t>(n) + 1, false);
  for (int k = 0; k < n; ++k) {
    row[k] = PairwiseCycleChi2(hypotheses_[k], hypothesis, chain) <= chi2_gate_;
    adjacent_[k].push_back(row[k]);
  }
  hypotheses_.push_back(hypothesis);
  adjacent_.push_back(std::move(row));

  const bool fits_all =
      std::all_of(kept_.begin(), kept_.end(), [&](int k) { return adjacent_[n][k]; });
  if (fits_all) {
    kept_.push_back(n);
    return false;
  }
  // The kept set is a maximum clique of the hypotheses before this one, so a larger clique must
  // contain the newcomer: search among its consistent partners only.
  std::vector<int> partners;
  for (int k = 0; k < n; ++k) {
    if (adjacent_[n][k]) partners.push_back(k);
  }
  if (static_cast<int>(partners.size()) < static_cast<int>(kept_.size())) return false;
  std::vector<std::vector<bool>> sub(partners.size(), std::vector<bool>(partners.size(), false));
  for (std::size_t u = 0; u < partners.size(); ++u) {
    for (std::size_t w = 0; w < partners.size(); ++w) {
      sub[u][w] = u != w && adjacent_[partners[u]][partners[w]];
    }
  }
  const std::vector<int> clique = MaximumClique(sub, 200000);
  if (clique.size() + 1 <= kept_.size()) return false;
  kept_.clear();
  for (const int u : clique) kept_.push_back(partners[static_cast<std::size_t>(u)]);
  kept_.push_back(n);
  std::sort(kept_.begin(), kept_.end());
  return true;
}

namespace {

// Tomita and Seki's MCQ: candidates sorted by a greedy colouring, whose colour numbers bound the
// clique any suffix can still give.
class CliqueSearch {
 public:
  CliqueSearch(const std::vector<std::vector<bool>>& adjacent, long max_steps)
      : adjacent_(adjacent), max_steps_(max_steps) {}

  std::vector<int> Run() {
    const int n = static_cast<int>(adjacent_.size());
    std::vector<int> degree(static_cast<std::size_t>(n), 0);
    for (int u = 0; u < n; ++u) {
      for (int w = 0; w < n; ++w) degree[u] += adjacent_[u][w];
    }
    std::vector<int> candidates(static_cast<std::size_t>(n));
    std::iota(candidates.begin(), candidates.end(), 0);
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](int u, int w) { return degree[u] > degree[w]; });
    std::vector<int> clique;
    Expand(&clique, candidates);
    std::sort(best_.begin(), best_.end());
    return best_;
  }

 private:
  void Expand(std::vector<int>* clique, const std::vector<int>& candidates) {
    std::vector<int> order;
    std::vector<int> colour;
    Colour(candidates, &order, &colour);
    for (int i = static_cast<int>(order.size()) - 1; i >= 0; --i) {
      if (clique->size() + static_cast<std::size_t>(colour[i]) <= best_.size()) return;
      if (++steps_ > max_steps_) return;
      const int v = order[i];
      clique->push_back(v);
      std::vector<int> next;
      for (int k = 0; k < i; ++k) {
        if (adjacent_[v][order[k]]) next.push_back(order[k]);
      }
      if (next.empty()) {
        if (clique->size() > best_.size()) best_ = *clique;
      } else {
        Expand(clique, next);
      }
      clique->pop_back();
    }
  }

  // Greedy colouring in the given order; `order` lists the vertices by colour class, `colour`
  // their class numbers from 1.
  void Colour(const std::vector<int>& candidates, std::vector<int>* order,
              std::vector<int>* colour) const {
    std::vector<std::vector<int>> classes;
    for (const int v : candidates) {
      std::size_t c = 0;
      for (; c < classes.size(); ++c) {
        const bool clash = std::any_of(classes[c].begin(), classes[c].end(),
                                       [&](int w) { return adjacent_[v][w]; });
        if (!clash) break;
      }
      if (c == classes.size()) classes.emplace_back();
      classes[c].push_back(v);
    }
    for (std::size_t c = 0; c < classes.size(); ++c) {
      for (const int v : classes[c]) {
        order->push_back(v);
        colour->push_back(static_cast<int>(c) + 1);
      }
    }
  }

  const std::vector<std::vector<bool>>& adjacent_;
  long max_steps_;
  long steps_ = 0;
  std::vector<int> best_;
};

}  // namespace

std::vector<int> MaximumClique(const std::vector<std::vector<bool>>& adjacent, long max_steps) {
  return CliqueSearch(adjacent, max_steps).Run();
}

}  // namespace slamrig::slam
