#include "slam/pipeline/revisits.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace slamrig::slam {
namespace {

// A 12 m x 8 m room with two pillars, its walls sampled every 5 cm.
std::vector<Eigen::Vector2d> Room() {
  std::vector<Eigen::Vector2d> walls;
  const auto segment = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
    const int steps = static_cast<int>((b - a).norm() / 0.05);
    for (int i = 0; i <= steps; ++i) walls.push_back(a + (b - a) * i / steps);
  };
  const auto box = [&](double x0, double y0, double x1, double y1) {
    segment({x0, y0}, {x1, y0});
    segment({x1, y0}, {x1, y1});
    segment({x1, y1}, {x0, y1});
    segment({x0, y1}, {x0, y0});
  };
  box(0.0, 0.0, 12.0, 8.0);
  box(4.0, 3.5, 5.0, 4.5);
  box(7.5, 3.0, 8.0, 5.0);
  return walls;
}

// Somewhere else: short walls at random (seeded) around the room, none within 1.5 m of it, so
// that no shift within max_shift_m lays them on the room's. What the robot sees when its
// estimate says it is back but it is not.
std::vector<Eigen::Vector2d> Elsewhere() {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> x(-8.0, 20.0), y(-8.0, 16.0), angle(0.0, M_PI);
  std::vector<Eigen::Vector2d> walls;
  for (int w = 0; w < 80; ++w) {
    const double ax = x(random);
    const double ay = y(random);
    const Eigen::Vector2d a(ax, ay);
    const double t = angle(random);
    for (int i = 0; i <= 20; ++i) {
      const Eigen::Vector2d p = a + 0.05 * i * Eigen::Vector2d(std::cos(t), std::sin(t));
      const double dx = std::max({-p.x(), 0.0, p.x() - 12.0});
      const double dy = std::max({-p.y(), 0.0, p.y() - 8.0});
      if (std::hypot(dx, dy) >= 1.5) walls.push_back(p);
    }
  }
  return walls;
}

// Two laps of a rectangle inside the room, a pose every 0.5 m, heading along the path.
std::vector<Pose2> TwoLaps() {
  const std::vector<Eigen::Vector2d> corners = {{2, 2}, {10, 2}, {10, 6}, {2, 6}};
  std::vector<Pose2> poses;
  for (int lap = 0; lap < 2; ++lap) {
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector2d a = corners[c], b = corners[(c + 1) % 4];
      const double heading = std::atan2(b.y() - a.y(), b.x() - a.x());
      const int steps = static_cast<int>((b - a).norm() / 0.5);
      for (int i = 0; i < steps; ++i) {
        const Eigen::Vector2d p = a + (b - a) * i / steps;
        poses.emplace_back(p.x(), p.y(), heading);
      }
    }
  }
  return poses;
}

// What a 360-degree scanner of 8 m range sees of `world` from `pose`, in its own frame (no
// occlusion: the check does not depend on it).
std::vector<Eigen::Vector2d> View(const std::vector<Eigen::Vector2d>& world, const Pose2& pose) {
  std::vector<Eigen::Vector2d> points;
  const Pose2 inverse = pose.Inverse();
  for (const Eigen::Vector2d& p : world) {
    if ((p - pose.translation()).norm() <= 8.0) points.push_back(inverse * p);
  }
  return points;
}

struct Views {
  std::vector<Pose2> estimate;
  std::vector<std::vector<Eigen::Vector2d>> points;
};

// Scans taken at the true poses; the second lap's estimate moved by `second_lap_error` (applied
// on the left: a map-frame error, as a map out of true has).
Views TwoLapsWithSecondLapOff(const Pose2& second_lap_error) {
  const std::vector<Eigen::Vector2d> room = Room();
  const std::vector<Pose2> truth = TwoLaps();
  Views run;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const bool second_lap = k >= truth.size() / 2;
    run.estimate.push_back(second_lap ? second_lap_error * truth[k] : truth[k]);
    run.points.push_back(View(room, truth[k]));
  }
  return run;
}

// The second lap driven elsewhere, its estimate laid over the first lap's: a map drawn twice.
Views SecondLapElsewhere() {
  Views run = TwoLapsWithSecondLapOff(Pose2());
  const std::vector<Eigen::Vector2d> elsewhere = Elsewhere();
  for (std::size_t k = run.points.size() / 2; k < run.points.size(); ++k) {
    run.points[k] = View(elsewhere, run.estimate[k]);
  }
  return run;
}

TEST(RevisitsTest, AMapThatIsRightAgreesWhereverTheRobotCameBack) {
  const Views run = TwoLapsWithSecondLapOff(Pose2());
  const RevisitAgreement agreement = CheckRevisits(run.estimate, run.points);
  // Every pose of the second lap is a revisit of the first (48 poses a lap), and a few of the
  // first lap's own last poses are not (the lap is 24 m, over min_path_m).
  EXPECT_GE(agreement.revisits, 48);
  EXPECT_EQ(agreement.disagreeing, 0);
  EXPECT_FALSE(agreement.contradicts({}));
}

TEST(RevisitsTest, ASecondCopyOfTheMapDisagreesAtEveryRevisit) {
  const Views twice = SecondLapElsewhere();
  const RevisitAgreement agreement = CheckRevisits(twice.estimate, twice.points);
  EXPECT_GE(agreement.revisits, 48);
  EXPECT_EQ(agreement.disagreeing, agreement.revisits);
  EXPECT_EQ(agreement.shifted, 0);
  EXPECT_TRUE(agreement.contradicts({}));
  ASSERT_FALSE(agreement.disagreeing_views.empty());
  EXPECT_GE(agreement.disagreeing_views.front(), 48);
}

TEST(RevisitsTest, AMapOffByLessThanTheShiftIsOutNotTwice) {
  // Half a metre off along both axes (0.71 m): no wall of the second lap lands on the first's
  // until the shift that undoes it.
  const Views off = TwoLapsWithSecondLapOff(Pose2(0.5, 0.5, 0.0));
  const RevisitAgreement agreement = CheckRevisits(off.estimate, off.points);
  EXPECT_GE(agreement.revisits, 48);
  EXPECT_EQ(agreement.shifted, agreement.revisits);
  EXPECT_EQ(agreement.disagreeing, 0);
  RevisitRules no_shift;
  no_shift.max_shift_m = 0.0;
  const RevisitAgreement unshifted = CheckRevisits(off.estimate, off.points, no_shift);
  EXPECT_EQ(unshifted.disagreeing, unshifted.revisits);
  EXPECT_TRUE(unshifted.contradicts(no_shift));
}

TEST(RevisitsTest, AnErrorUnderACellAgrees) {
  // 0.17 m and 0.3 degrees: what a good map holds, where revisits must not count against it.
  const Views run = TwoLapsWithSecondLapOff(Pose2(0.12, -0.12, 0.005));
  const RevisitAgreement agreement = CheckRevisits(run.estimate, run.points);
  EXPECT_GE(agreement.revisits, 48);
  EXPECT_EQ(agreement.disagreeing, 0);
}

TEST(RevisitsTest, OnlyViewsFarAlongThePathAndFacingAlikeAreCompared) {
  const std::vector<Eigen::Vector2d> room = Room();
  // Standing still: the same place, but never min_path_m apart.
  std::vector<Pose2> still(30, Pose2(5.0, 2.0, 0.0));
  std::vector<std::vector<Eigen::Vector2d>> points(30, View(room, still.front()));
  EXPECT_EQ(CheckRevisits(still, points).revisits, 0);

  // Down a line and back facing the other way: the places repeat, the headings do not.
  std::vector<Pose2> there_and_back;
  for (int i = 0; i <= 16; ++i) there_and_back.emplace_back(2.0 + 0.5 * i, 2.0, 0.0);
  for (int i = 16; i >= 0; --i) there_and_back.emplace_back(2.0 + 0.5 * i, 2.0, M_PI);
  points.clear();
  for (const Pose2& p : there_and_back) points.push_back(View(room, p));
  EXPECT_EQ(CheckRevisits(there_and_back, points).revisits, 0);
  RevisitRules any_heading;
  any_heading.max_turn_rad = M_PI;
  const RevisitAgreement agreement = CheckRevisits(there_and_back, points, any_heading);
  EXPECT_GT(agreement.revisits, 0);
  EXPECT_EQ(agreement.disagreeing, 0);
}

TEST(RevisitsTest, DisagreementInOnePlaceIsClutterNotASecondCopy) {
  // The second lap sees something else over its first 4 m only (a passer-by, a turn on the spot
  // scanning the floor): its views there disagree, in 4-5 places of 1 m.
  Views run = TwoLapsWithSecondLapOff(Pose2());
  const Views twice = SecondLapElsewhere();
  for (int k = 48; k < 56; ++k) run.points[k] = twice.points[k];
  const RevisitAgreement agreement = CheckRevisits(run.estimate, run.points);
  EXPECT_GE(agreement.disagreeing, 6);
  EXPECT_LE(agreement.disagreeing_places, 5);
  RevisitRules rules;
  rules.min_disagreeing_places = agreement.disagreeing_places + 1;
  EXPECT_FALSE(agreement.contradicts(rules));
  rules.min_disagreeing_places = agreement.disagreeing_places;
  EXPECT_TRUE(agreement.contradicts(rules));  // 8 of 48: over 1 %
  rules.max_disagreeing_share = 0.2;
  EXPECT_FALSE(agreement.contradicts(rules));
}

TEST(RevisitsTest, AFilterKeepsAViewEveryHalfMetreAndChecksItsFinalPoses) {
  // Two laps at 0.1 m a scan: five times the views CheckRevisits is given above.
  const std::vector<Eigen::Vector2d> room = Room();
  const std::vector<Pose2> corners = TwoLaps();
  std::vector<Pose2> truth;
  for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
    const Pose2 step = corners[k].Between(corners[k + 1]);
    for (int i = 0; i < 5; ++i) {
      truth.push_back(corners[k] * Pose2(step.x() * i / 5.0, step.y() * i / 5.0, 0.0));
    }
  }
  RevisitViews views;
  int kept = 0;
  for (const Pose2& pose : truth) {
    if (views.Offer(pose)) {
      views.Keep(View(room, pose));
      ++kept;
    }
  }
  // A view every 0.5 m, or the scan after it when 0.5 m falls between scans (and each corner's
  // turn starts a new one).
  EXPECT_GE(kept, static_cast<int>(truth.size()) / 6 - 1);
  EXPECT_LE(kept, static_cast<int>(truth.size()) / 5 + 8);
  const RevisitAgreement right = views.Check(truth);
  EXPECT_GE(right.revisits, 40);
  EXPECT_EQ(right.disagreeing, 0);
  // The second lap driven elsewhere, its final poses laid over the first lap's: the views
  // disagree there.
  const std::vector<Eigen::Vector2d> other = Elsewhere();
  RevisitViews elsewhere;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    if (elsewhere.Offer(truth[k])) {
      elsewhere.Keep(View(k < truth.size() / 2 ? room : other, truth[k]));
    }
  }
  const RevisitAgreement wrong = elsewhere.Check(truth);
  EXPECT_GE(wrong.disagreeing, 10);
  EXPECT_TRUE(wrong.contradicts({}));
}

}  // namespace
}  // namespace slamrig::slam
