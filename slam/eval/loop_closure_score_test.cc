#include "slam/eval/loop_closure_score.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamrig::slam {
namespace {

// A square lap of side 5 m walked twice in 0.25 m steps (80 scans per lap): the second lap
// revisits every place of the first, 20 m of path later.
std::vector<Pose2> TwoLaps() {
  std::vector<Pose2> poses;
  for (int lap = 0; lap < 2; ++lap) {
    for (int side = 0; side < 4; ++side) {
      const double yaw = side * M_PI / 2.0;
      const Eigen::Vector2d corners[4] = {{0, 0}, {5, 0}, {5, 5}, {0, 5}};
      for (int k = 0; k < 20; ++k) {
        const Eigen::Vector2d p =
            corners[side] + 0.25 * k * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
        poses.emplace_back(p.x(), p.y(), yaw);
      }
    }
  }
  return poses;
}

TEST(LoopClosureScoreTest, TrueClosureAgreesWithTheReferenceWithinTolerance) {
  const std::vector<Pose2> ref = TwoLaps();
  const Pose2 exact = ref[10].Between(ref[92]);
  // Off by 0.2 m and 0.05 rad: still true; off by 0.5 m: false; off by 0.2 rad: false.
  const std::vector<LoopClosure> closures = {
      {10, 92, exact * Pose2(0.2, 0.0, 0.05)},
      {10, 92, exact * Pose2(0.0, 0.5, 0.0)},
      {20, 101, ref[20].Between(ref[101]) * Pose2(0.0, 0.0, 0.2)},
      {5, 500, exact},  // outside the reference
  };
  const LoopClosureScore s = ScoreLoopClosures(closures, ref);
  EXPECT_EQ(s.closures, 4);
  EXPECT_EQ(s.false_closures, 3);
  EXPECT_DOUBLE_EQ(s.precision, 0.25);
  ASSERT_EQ(s.is_true.size(), 4u);
  EXPECT_TRUE(s.is_true[0]);
  EXPECT_FALSE(s.is_true[1]);
  ASSERT_EQ(s.false_ones.size(), 3u);
  EXPECT_EQ(s.false_ones[2].to_scan, 500);
}

TEST(LoopClosureScoreTest, RecallCountsRevisitEpisodes) {
  const std::vector<Pose2> ref = TwoLaps();
  // One episode: from the end of the first lap (back within 1 m of the start) through the whole
  // second lap, every pose is near one more than 10 m of path earlier.
  const LoopClosureScore none = ScoreLoopClosures({}, ref);
  EXPECT_EQ(none.revisit_episodes, 1);
  EXPECT_EQ(none.recalled_episodes, 0);
  EXPECT_DOUBLE_EQ(none.recall, 0.0);
  EXPECT_DOUBLE_EQ(none.precision, 1.0);

  const LoopClosureScore one = ScoreLoopClosures({{3, 120, ref[3].Between(ref[120])}}, ref);
  EXPECT_EQ(one.recalled_episodes, 1);
  EXPECT_DOUBLE_EQ(one.recall, 1.0);

  // A false closure does not recall the episode.
  const LoopClosureScore wrong = ScoreLoopClosures({{3, 120, Pose2(9, 9, 0)}}, ref);
  EXPECT_DOUBLE_EQ(wrong.recall, 0.0);
}

TEST(LoopClosureScoreTest, OneLapHasNoRevisit) {
  std::vector<Pose2> ref = TwoLaps();
  ref.resize(70);  // ends 2.75 m short of the start
  const LoopClosureScore s = ScoreLoopClosures({}, ref);
  EXPECT_EQ(s.revisit_episodes, 0);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
}

TEST(LoopClosureScoreTest, OptionsAreValidated) {
  LoopClosureScoreOptions o;
  EXPECT_TRUE(o.Validate().empty());
  o.tolerance_m = 0.0;
  ASSERT_EQ(o.Validate().size(), 1u);
  EXPECT_EQ(o.Validate()[0], "tolerance_m = 0; must be > 0");
}

}  // namespace
}  // namespace slamrig::slam
