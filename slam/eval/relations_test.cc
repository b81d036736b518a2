#include "slam/eval/relations.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

Trajectory Square() {
  Trajectory t;
  Pose2 pose;
  for (int i = 0; i < 80; ++i) {
    t.Append(Time::FromSeconds(0.5 * i), pose);
    pose = pose * Pose2(0.5, 0.0, i % 10 == 9 ? 1.5707963267948966 : 0.0);
  }
  return t;
}

TEST(RelationsTest, GeneratedRelationsScoreTheirOwnTrajectoryZero) {
  const Trajectory truth = Square();
  RelationGeneratorOptions options;
  options.path_distances_m = {2.0, 10.0};
  options.num_random_pairs = 50;
  const std::vector<Relation> relations = GenerateRelations(truth, options);
  // 79 consecutive, 76 reaching 2 m (4 steps), 60 reaching 10 m (20 steps), up to 50 random.
  EXPECT_GE(relations.size(), 79u + 76u + 60u + 45u);
  EXPECT_LE(relations.size(), 79u + 76u + 60u + 50u);
  const RelationsResult r = EvaluateRelations(truth, relations);
  EXPECT_EQ(r.skipped, 0);
  EXPECT_LT(r.translation_m.max, 1e-9);
  EXPECT_LT(r.rotation_rad.max, 1e-9);
}

// A constant heading error on one pose shows up in exactly the relations that span it.
TEST(RelationsTest, ErrorsAreMeanAndStdOfAbsoluteAndSquaredErrors) {
  const Trajectory truth = Square();
  const std::vector<Relation> relations = GenerateRelations(truth, RelationGeneratorOptions{});
  Trajectory estimate;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Pose2& p = truth[i].pose;
    estimate.Append(truth[i].time, i == 40 ? Pose2(p.x() + 0.1, p.y(), p.theta()) : p);
  }
  const RelationsResult r = EvaluateRelations(estimate, relations);
  ASSERT_EQ(r.used, 79);
  // Relations (39, 40) and (40, 41) each carry a 0.1 m error, the others none.
  EXPECT_NEAR(r.translation_m.mean, 0.2 / 79, 1e-9);
  EXPECT_NEAR(r.translation_sq_m2.mean, 0.02 / 79, 1e-9);
  EXPECT_NEAR(r.translation_m.std_dev, std::sqrt(0.02 / 79 - std::pow(0.2 / 79, 2)), 1e-9);
  EXPECT_NEAR(r.rotation_rad.max, 0.0, 1e-12);
}

TEST(RelationsTest, FormatParseRoundTripAndErrors) {
  const std::vector<Relation> relations = {
      {Time::FromSeconds(1.5), Time::FromSeconds(2.25), Pose2(0.5, -0.25, 0.125)}};
  const std::vector<Relation> back =
      ParseRelations("# comment\n" + FormatRelations(relations), "r.txt");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].t2, Time::FromSeconds(2.25));
  EXPECT_NEAR(back[0].relative.y(), -0.25, 1e-9);
  EXPECT_NEAR(back[0].relative.theta(), 0.125, 1e-9);
  try {
    ParseRelations("1 2 3 4 0 0 x 0\n", "r.txt");
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_STREQ(e.what(), "r.txt:1: pitch: expected a number (`t1 t2 x y z roll pitch yaw`)");
  }
}

}  // namespace
}  // namespace slamrig::slam
