#include "slam/graph/trajectory_graph.h"

#include <gtest/gtest.h>

#include "slam/graph/edge_error.h"
#include "slam/graph/g2o_io.h"
#include "slam/graph/pose_graph_optimizer.h"
#include "tests/util/temp_dir.h"

namespace slamrig::slam {
namespace {

Trajectory Square() {
  Trajectory t;
  Pose2 p(2.0, 1.0, 0.3);
  for (int i = 0; i < 12; ++i) {
    t.Append(Time::FromSeconds(i), p);
    p = p * Pose2(1.0, 0.0, i % 3 == 2 ? 1.5707963267948966 : 0.0);
  }
  return t;
}

TEST(TrajectoryGraphTest, ChainHasZeroErrorAndWritesAsG2o) {
  const Trajectory t = Square();
  const Eigen::Matrix3d info = Eigen::Vector3d(100.0, 100.0, 400.0).asDiagonal();
  PoseGraph g = PoseGraphFromTrajectory(t, info);
  ASSERT_EQ(g.vertices().size(), 12u);
  ASSERT_EQ(g.edges().size(), 11u);
  EXPECT_TRUE(g.vertex(0).fixed);
  EXPECT_EQ(g.edges()[3].kind, EdgeKind::kOdometry);
  EXPECT_LT(Chi2(g), 1e-20);
  // The loop closes: the last pose is one step before the first.
  AddRelativePoseEdge(&g, 11, 0, t[11].pose.Between(t[0].pose), info);
  EXPECT_EQ(g.edges().back().kind, EdgeKind::kLoopClosure);
  EXPECT_LT(Chi2(g), 1e-20);

  testing::TempDir dir;
  WriteG2o(dir.File("square.g2o"), g);
  PoseGraph back = ReadG2o(dir.File("square.g2o"));
  EXPECT_EQ(FormatG2o(back), FormatG2o(g));
  // Nothing to correct: the optimiser leaves the poses (within rounding) where they are.
  PoseGraphOptimizer({}).Optimize(&back);
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(back.pose(static_cast<int>(i)).x(), t[i].pose.x(), 1e-9);
    EXPECT_NEAR(back.pose(static_cast<int>(i)).y(), t[i].pose.y(), 1e-9);
  }
}

}  // namespace
}  // namespace slamrig::slam
