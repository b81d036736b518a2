// Data association of range-bearing observations to mapped landmarks: individual Mahalanobis
// gating with nearest neighbour, and Joint Compatibility Branch and Bound (Neira and Tardos,
// "Data association in stochastic mapping using the joint compatibility test", IEEE Trans.
// Robot. Automat. 17(6), 2001, Sec. III: Eq. 10 for the joint Mahalanobis distance, Fig. 3 for
// the search), which takes the correlation between the predicted landmarks into account.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace slamrig::slam {

/// Observations and the landmarks' predicted observations, all (range_m, bearing_rad).
struct AssociationProblem {
  std::vector<Eigen::Vector2d> observations;
  std::vector<Eigen::Matrix2d> observation_covariances;  ///< one per observation
  std::vector<Eigen::Vector2d> predictions;              ///< h_j for landmark j
  /// The joint covariance H P H^T of all predictions, 2m x 2m (landmark j at rows 2j, 2j + 1).
  Eigen::MatrixXd prediction_covariance;
  double gate_probability = 0.99;  ///< chi-square gate of individual and joint compatibility
};

/// What an association found: for each observation its landmark, or -1.
struct Association {
  std::vector<int> landmark_of_observation;
  int pairings = 0;
  double joint_distance = 0.0;  ///< joint squared Mahalanobis distance of the pairings
};

/// Each observation to the individually compatible landmark of least Mahalanobis distance
/// (landmarks may be taken twice, as nearest neighbour does).
Association NearestNeighbour(const AssociationProblem& problem);

/// The largest jointly compatible set of pairings (ties: the smallest joint distance).
Association JointCompatibility(const AssociationProblem& problem);

}  // namespace slamrig::slam
