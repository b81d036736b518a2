#include "slam/fusion/data_association.h"

#include <Eigen/Cholesky>
#include <limits>

#include "slam/fusion/consistency.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {
namespace {

Eigen::Vector2d Innovation(const AssociationProblem& p, int i, int j) {
  Eigen::Vector2d v = p.observations[i] - p.predictions[j];
  v(1) = NormalizeAngle(v(1));
  return v;
}

double IndividualDistance(const AssociationProblem& p, int i, int j) {
  const Eigen::Matrix2d s =
      p.prediction_covariance.block<2, 2>(2 * j, 2 * j) + p.observation_covariances[i];
  const Eigen::Vector2d v = Innovation(p, i, j);
  return v.dot(s.ldlt().solve(v));
}

// Eq. 10: the stacked innovation of the pairings against their joint covariance.
double JointDistance(const AssociationProblem& p, const std::vector<int>& pairing) {
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < static_cast<int>(pairing.size()); ++i)
    if (pairing[i] >= 0) pairs.push_back({i, pairing[i]});
  const int k = static_cast<int>(pairs.size());
  if (k == 0) return 0.0;
  Eigen::VectorXd v(2 * k);
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(2 * k, 2 * k);
  for (int a = 0; a < k; ++a) {
    v.segment<2>(2 * a) = Innovation(p, pairs[a].first, pairs[a].second);
    for (int b = 0; b < k; ++b) {
      s.block<2, 2>(2 * a, 2 * b) =
          p.prediction_covariance.block<2, 2>(2 * pairs[a].second, 2 * pairs[b].second);
    }
    s.block<2, 2>(2 * a, 2 * a) += p.observation_covariances[pairs[a].first];
  }
  return v.dot(s.ldlt().solve(v));
}

struct Search {
  const AssociationProblem& problem;
  std::vector<std::vector<bool>> compatible;  // individual compatibility, observation x landmark
  Association best;
  std::vector<int> current;

  void Run(int i, int pairings) {
    const int n = static_cast<int>(problem.observations.size());
    if (i == n) {
      const double d = JointDistance(problem, current);
      if (pairings > best.pairings || (pairings == best.pairings && d < best.joint_distance)) {
        best = {current, pairings, d};
      }
      return;
    }
    // Bound: even pairing every remaining observation cannot beat the best.
    if (pairings + (n - i) < best.pairings) return;
    for (int j = 0; j < static_cast<int>(problem.predictions.size()); ++j) {
      if (!compatible[i][j]) continue;
      bool taken = false;
      for (int a = 0; a < i; ++a) taken = taken || current[a] == j;
      if (taken) continue;
      current[i] = j;
      const int k = pairings + 1;
      if (JointDistance(problem, current) < ChiSquareQuantile(problem.gate_probability, 2.0 * k)) {
        Run(i + 1, k);
      }
      current[i] = -1;
    }
    // The observation left unpaired (a new landmark or spurious), if that can still win.
    if (pairings + (n - i - 1) >= best.pairings) Run(i + 1, pairings);
  }
};

}  // namespace

Association NearestNeighbour(const AssociationProblem& problem) {
  const int n = static_cast<int>(problem.observations.size());
  const double gate = ChiSquareQuantile(problem.gate_probability, 2.0);
  Association out;
  out.landmark_of_observation.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    double best = gate;
    for (int j = 0; j < static_cast<int>(problem.predictions.size()); ++j) {
      const double d = IndividualDistance(problem, i, j);
      if (d < best) {
        best = d;
        out.landmark_of_observation[i] = j;
      }
    }
    out.pairings += out.landmark_of_observation[i] >= 0;
  }
  out.joint_distance = JointDistance(problem, out.landmark_of_observation);
  return out;
}

Association JointCompatibility(const AssociationProblem& problem) {
  const int n = static_cast<int>(problem.observations.size());
  const int m = static_cast<int>(problem.predictions.size());
  const double gate = ChiSquareQuantile(problem.gate_probability, 2.0);
  Search search{problem, {}, {}, std::vector<int>(n, -1)};
  search.compatible.assign(n, std::vector<bool>(m, false));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) search.compatible[i][j] = IndividualDistance(problem, i, j) < gate;
  search.best.landmark_of_observation.assign(n, -1);
  search.best.joint_distance = std::numeric_limits<double>::infinity();
  search.Run(0, 0);
  return search.best;
}

}  // namespace slamrig::slam
