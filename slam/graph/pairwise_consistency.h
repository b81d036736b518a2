#pragma once

// Pairwise consistency maximisation of loop closures (Mangelson, Dominic, Eustice and Vasudevan,
// "Pairwise Consistent Measurement Set Maximization for Robust Multi-robot Map Merging", ICRA
// 2018, Sec. IV; Olson's single-cluster graph partitioning, 2009, tests the same cycles). Two
// closures a = (i_a -> j_a, Z_a) and b = (i_b -> j_b, Z_b) are consistent when the cycle
//   i_a --Z_a--> j_a --odometry--> j_b --Z_b^-1--> i_b --odometry--> i_a
// returns to where it started within its uncertainty (a chi2 test on the cycle's error). The
// closures kept are the largest set that is consistent pair by pair: a maximum clique of the
// consistency graph. An aliased place gives closures that each look right on their own but
// disagree with the true ones through the odometry between them; the true closures, being many
// and mutually consistent, form the larger clique.

#include <Eigen/Core>
#include <vector>

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The odometry chain of a pose graph: node k's pose by composing the odometry edges from node 0,
/// with each edge's (xy, yaw) variance, for the uncertainty of any stretch of it in O(1) (prefix
/// sums). Not the optimised poses: consistency must not depend on the closures it judges.
class OdometryChain {
 public:
  /// Starts the chain at node 0 (the identity).
  OdometryChain();
  /// Appends node size() after `relative` (from the last node), with the edge's variances.
  void Append(const Pose2& relative, double variance_xy, double variance_yaw);
  int size() const { return static_cast<int>(poses_.size()); }
  const Pose2& pose(int k) const { return poses_[static_cast<std::size_t>(k)]; }
  /// Variance (xy, yaw) of the chain between nodes a and b (either order): every edge's xy
  /// variance plus its yaw variance times the squared lever from its node to `lever_end`
  /// (a point in the chain's frame), where a heading error there moves the cycle's end.
  Eigen::Vector2d StretchVariance(int a, int b, const Eigen::Vector2d& lever_end) const;

 private:
  std::vector<Pose2> poses_;
  // Prefix sums over edges 1..k (edge k ends at node k) of: xy variance, yaw variance, yaw
  // variance times the node's position, yaw variance times its squared norm.
  std::vector<double> xy_;
  std::vector<double> yaw_;
  std::vector<Eigen::Vector2d> yaw_p_;
  std::vector<double> yaw_p2_;
};

/// A loop closure hypothesis: the pose of node `to` in node `from`'s frame and its covariance
/// (x, y, theta).
struct ClosureHypothesis {
  int from = 0;
  int to = 0;
  Pose2 measurement;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

/// The chi2 (3 dof) of the cycle through closures a and b and the chain between their ends.
double PairwiseCycleChi2(const ClosureHypothesis& a, const ClosureHypothesis& b,
                         const OdometryChain& chain);

/// The consistency graph of a growing set of hypotheses and a large clique of it. Deterministic.
class PairwiseConsistency {
 public:
  /// Pairs whose cycle chi2 is at most `chi2_gate` are consistent.
  explicit PairwiseConsistency(double chi2_gate) : chi2_gate_(chi2_gate) {}

  /// Adds hypothesis number size() (its ends must be nodes of `chain`), tests it against every
  /// earlier one, and updates the kept set: the newcomer joins when it is consistent with every
  /// kept hypothesis; otherwise a maximum clique is searched again and replaces the kept set when
  /// it is larger. Returns true when the kept set changed other than by appending the newcomer.
  bool Add(const ClosureHypothesis& hypothesis, const OdometryChain& chain);

  /// Indices (in Add order, ascending) of the hypotheses kept.
  const std::vector<int>& kept() const { return kept_; }
  bool consistent(int a, int b) const { return adjacent_[a][b]; }
  int size() const { return static_cast<int>(hypotheses_.size()); }

 private:
  double chi2_gate_;
  std::vector<ClosureHypothesis> hypotheses_;
  std::vector<std::vector<bool>> adjacent_;
  std::vector<int> kept_;
};

/// A maximum clique of the graph `adjacent` (symmetric, no self loops): exact branch and bound
/// with greedy-colouring bounds (Tomita and Seki 2003) over at most `max_steps` expansions, the
/// best clique found so far when the budget runs out. Ascending indices; ties go to the clique
/// found first, which is deterministic.
std::vector<int> MaximumClique(const std::vector<std::vector<bool>>& adjacent, long max_steps);

}  // namespace slamrig::slam
