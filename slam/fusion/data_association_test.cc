#include "slam/fusion/data_association.h"

#include <gtest/gtest.h>

namespace slamrig::slam {
namespace {

// Two landmarks whose predictions are strongly correlated (both move with the robot's pose
// error). The observations are each within their landmark's individual gate, but displaced in
// opposite directions, which no common pose error explains: nearest neighbour accepts both,
// joint compatibility keeps only one of them.
AssociationProblem CorrelatedPair() {
  AssociationProblem p;
  p.predictions = {{4.0, 0.3}, {4.5, -0.2}};
  Eigen::MatrixXd cov(4, 4);
  const double v = 0.04, c = 0.039;  // correlation 0.975 in range between the two landmarks
  cov << v, 0, c, 0,                 //
      0, 1e-4, 0, 0,                 //
      c, 0, v, 0,                    //
      0, 0, 0, 1e-4;
  p.prediction_covariance = cov;
  p.observations = {{4.0 + 0.35, 0.3}, {4.5 - 0.35, -0.2}};
  p.observation_covariances = {Eigen::Matrix2d::Identity() * 1e-4,
                               Eigen::Matrix2d::Identity() * 1e-4};
  return p;
}

TEST(DataAssociationTest, JcbbRejectsASpuriousPairingThatNearestNeighbourAccepts) {
  const AssociationProblem p = CorrelatedPair();
  const Association nn = NearestNeighbour(p);
  EXPECT_EQ(nn.landmark_of_observation, (std::vector<int>{0, 1}));
  const Association jc = JointCompatibility(p);
  EXPECT_EQ(jc.pairings, 1);
  // The joint distance of NN's pairing is far beyond chi2_4's gate; JCBB's is within chi2_2's.
  EXPECT_GT(nn.joint_distance, 13.28);
  EXPECT_LT(jc.joint_distance, 9.21);
}

TEST(DataAssociationTest, JcbbAcceptsACommonShiftThatTheCorrelationExplains) {
  AssociationProblem p = CorrelatedPair();
  p.observations = {{4.0 + 0.35, 0.3}, {4.5 + 0.35, -0.2}};  // the same shift: a pose error
  const Association jc = JointCompatibility(p);
  EXPECT_EQ(jc.landmark_of_observation, (std::vector<int>{0, 1}));
}

}  // namespace
}  // namespace slamrig::slam
