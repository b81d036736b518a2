#include "slam/eval/landmark_score.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

ScoredLandmark At(double x, double y, double variance) {
  return {Eigen::Vector2d(x, y), variance * Eigen::Matrix2d::Identity()};
}

// Three pillars, two mapped (errors 0.1 and 0.2 m), one landmark far from every pillar: the
// errors, NEES and counts against a hand computation.
TEST(LandmarkScoreTest, PairsMutualNearestWithinTheRadius) {
  const std::vector<Eigen::Vector2d> pillars = {{0, 0}, {5, 0}, {0, 5}};
  const std::vector<ScoredLandmark> landmarks = {At(0.1, 0, 0.01), At(5, 0.2, 0.04),
                                                 At(10, 10, 0.01)};
  const LandmarkScore s = ScoreLandmarks(pillars, landmarks, {}, Trajectory());
  EXPECT_EQ(s.pillars, 3);
  EXPECT_EQ(s.mapped, 2);
  EXPECT_EQ(s.spurious, 1);
  EXPECT_NEAR(s.error_max_m, 0.2, 1e-12);
  EXPECT_NEAR(s.error_mean_m, 0.15, 1e-12);
  EXPECT_NEAR(s.anees, (0.01 / 0.01 + 0.04 / 0.04) / 2, 1e-9);
  ASSERT_TRUE(s.anees_bounds);
  EXPECT_NEAR(s.anees_bounds->upper, AneesBounds(2, 2).upper, 1e-12);
  // A landmark 0.6 m off is beyond the default radius: nothing mapped, NaN errors.
  const LandmarkScore far = ScoreLandmarks({{0, 0}}, {At(0.6, 0, 0.01)}, {}, Trajectory());
  EXPECT_EQ(far.mapped, 0);
  EXPECT_EQ(far.spurious, 1);
  EXPECT_TRUE(std::isnan(far.error_mean_m));
  EXPECT_TRUE(std::isnan(far.anees));
  EXPECT_FALSE(far.anees_bounds);
}

// Sightings placed at the true pose: a landmark's pillar is its majority; a sighting of another
// pillar is a wrong association, and so is a clutter sighting far from its clutter landmark.
TEST(LandmarkScoreTest, WrongAssociationsAgainstTheMajorityPillar) {
  const std::vector<Eigen::Vector2d> pillars = {{2, 0}, {0, 2}};
  const std::vector<ScoredLandmark> landmarks = {At(2, 0, 0.01), At(0, 2, 0.01), At(9, 9, 0.01)};
  Trajectory truth;
  truth.Append(Time::FromSeconds(0), Pose2(0, 0, 0));
  truth.Append(Time::FromSeconds(10), Pose2(0, 0, M_PI / 2));
  // At t = 5 the robot faces 45 degrees: base (sqrt 2, -sqrt 2) is pillar (2, 0).
  const double r = std::sqrt(2.0);
  const std::vector<ScoredSighting> sightings = {
      {Time::FromSeconds(0), 0, {2, 0}},   // pillar 0: right
      {Time::FromSeconds(5), 0, {r, -r}},  // pillar 0 seen turned: right
      {Time::FromSeconds(0), 0, {0, 2}},   // pillar 1 given to landmark 0: wrong
      {Time::FromSeconds(0), 1, {0, 2}},   // right
      {Time::FromSeconds(1), 1, {0, 2}},   // right
      {Time::FromSeconds(0), 2, {9, 9}},   // clutter at its clutter landmark: right
      {Time::FromSeconds(0), 2, {7, 9}},   // clutter 2 m from it: wrong
      {Time::FromSeconds(20), 1, {0, 2}},  // no truth at t = 20: clutter vote, wrong for 1
  };
  const LandmarkScore s = ScoreLandmarks(pillars, landmarks, sightings, truth);
  EXPECT_EQ(s.sightings, 8);
  EXPECT_EQ(s.wrong_associations, 3);
  EXPECT_EQ(s.mapped, 2);
  EXPECT_EQ(s.spurious, 1);
}

}  // namespace
}  // namespace slamrig::slam
