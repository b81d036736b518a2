#include "slam/graph/graph_initialization.h"

#include <gtest/gtest.h>

#include "slam/graph/testing/random_graph.h"

namespace slamrig::slam {
namespace {

// Every vertex moved away from the truth, the first one kept.
void Scramble(PoseGraph* graph) {
  for (std::size_t i = 1; i < graph->vertices().size(); ++i) {
    graph->SetPose(graph->vertices()[i].id, Pose2(3.0 * static_cast<double>(i), -1.0, 2.0));
  }
}

void ExpectPosesNear(const PoseGraph& graph, const std::vector<Pose2>& truth, double tolerance) {
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Pose2& p = graph.vertices()[i].pose;
    EXPECT_NEAR(p.x(), truth[i].x(), tolerance) << i;
    EXPECT_NEAR(p.y(), truth[i].y(), tolerance) << i;
    EXPECT_NEAR(NormalizeAngle(p.theta() - truth[i].theta()), 0.0, tolerance) << i;
  }
}

TEST(GraphInitializationTest, ChordalIsExactWithoutNoise) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph(
      {.num_poses = 200, .loop_closure_probability = 0.5, .sigma_xy_m = 0, .sigma_theta_rad = 0});
  Scramble(&r.graph);
  const InitializationSummary s = InitializeChordal(&r.graph);
  EXPECT_EQ(s.vertices_set, 199);
  EXPECT_EQ(s.vertices_kept, 0);
  ExpectPosesNear(r.graph, r.truth, 1e-9);
}

TEST(GraphInitializationTest, ChordalKeepsAnchorsAndUnreachableVertices) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph(
      {.num_poses = 30, .sigma_xy_m = 0, .sigma_theta_rad = 0, .seed = 5});
  const Pose2 origin(1.0, 2.0, 0.5);
  r.graph.SetPose(0, origin);
  r.graph.AddVertex(100, Pose2(7, 7, 7));
  InitializeChordal(&r.graph);
  EXPECT_EQ(r.graph.pose(0), origin);
  EXPECT_EQ(r.graph.pose(100), Pose2(7, 7, 7));
  // Everything else is the truth seen from the moved first vertex.
  for (int i = 1; i < 30; ++i) {
    const Pose2 expected = origin * r.truth[i];
    EXPECT_NEAR(r.graph.pose(i).x(), expected.x(), 1e-9);
    EXPECT_NEAR(r.graph.pose(i).y(), expected.y(), 1e-9);
  }
}

TEST(GraphInitializationTest, OdometryComposesTheChain) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 40, .seed = 8});
  Scramble(&r.graph);
  const InitializationSummary s = InitializeFromOdometry(&r.graph);
  EXPECT_EQ(s.vertices_set, 39);
  EXPECT_EQ(s.vertices_kept, 0);
  Pose2 expected;
  for (const PoseGraphEdge& e : r.graph.edges()) {
    if (e.kind != EdgeKind::kOdometry) continue;
    expected = expected * e.measurement;
    const Pose2& p = r.graph.pose(e.to);
    EXPECT_NEAR(p.x(), expected.x(), 1e-12);
    EXPECT_NEAR(p.y(), expected.y(), 1e-12);
    EXPECT_NEAR(p.theta(), expected.theta(), 1e-12);
  }
}

TEST(GraphInitializationTest, OdometryUsesReversedEdgesAndKeepsGaps) {
  PoseGraph g;
  g.AddVertex(0, Pose2());
  g.AddVertex(1, Pose2(9, 9, 0));
  g.AddVertex(2, Pose2(5, 0, 0));
  g.AddVertex(3, Pose2(6, 0, 0.5));
  // 1 -> 0 reversed, no edge 1-2 (a gap), 2 -> 3 forward.
  g.AddEdge({.from = 1, .to = 0, .measurement = Pose2(-1, 0, 0)});
  g.AddEdge({.from = 2, .to = 3, .measurement = Pose2(2, 0, 0)});
  g.AddEdge({.from = 0, .to = 3, .measurement = Pose2(0, 0, 0)});
  const InitializationSummary s = InitializeFromOdometry(&g);
  EXPECT_EQ(s.vertices_set, 2);
  EXPECT_EQ(s.vertices_kept, 1);
  EXPECT_EQ(g.pose(1), Pose2(1, 0, 0));
  // The gap keeps 2's old offset from 1: (-4, -9).
  EXPECT_NEAR(g.pose(2).x(), -3.0, 1e-12);
  EXPECT_NEAR(g.pose(2).y(), -9.0, 1e-12);
  EXPECT_NEAR(g.pose(3).x(), -1.0, 1e-12);
}

}  // namespace
}  // namespace slamrig::slam
