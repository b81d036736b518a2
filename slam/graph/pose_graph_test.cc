#include "slam/graph/pose_graph.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace slamrig::slam {
namespace {

using ::testing::ElementsAre;

TEST(PoseGraphTest, KeepsInsertionOrderAndFindsIds) {
  PoseGraph g;
  EXPECT_TRUE(g.AnchorIndices().empty());
  g.AddVertex(42, Pose2(1, 0, 0));
  g.AddVertex(7, Pose2(2, 0, 0));
  g.AddVertex(9, Pose2(3, 0, 0), /*fixed=*/true);
  EXPECT_EQ(g.IndexOf(7), 1u);
  EXPECT_EQ(g.vertices()[g.IndexOf(9)].id, 9);
  EXPECT_THAT(g.AnchorIndices(), ElementsAre(2u));
  g.SetFixed(9, false);
  EXPECT_THAT(g.AnchorIndices(), ElementsAre(0u));
  g.SetPose(7, Pose2(5, 5, 1));
  EXPECT_EQ(g.pose(7), Pose2(5, 5, 1));
  EXPECT_FALSE(g.HasVertex(8));
}

TEST(PoseGraphDeathTest, RejectsBrokenInvariants) {
  PoseGraph g;
  g.AddVertex(0, Pose2());
  g.AddVertex(1, Pose2());
  EXPECT_DEATH(g.AddVertex(1, Pose2()), "duplicate vertex id");
  EXPECT_DEATH(g.AddEdge({.from = 0, .to = 5, .measurement = Pose2()}), "never added");
  EXPECT_DEATH(g.AddEdge({.from = 1, .to = 1, .measurement = Pose2()}), "to itself");
  PoseGraphEdge e{.from = 0, .to = 1, .measurement = Pose2()};
  e.information(2, 2) = -1.0;
  EXPECT_DEATH(g.AddEdge(e), "positive definite");
  EXPECT_DEATH(g.IndexOf(3), "unknown vertex id");
}

}  // namespace
}  // namespace slamrig::slam
