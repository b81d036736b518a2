#include "slam/graph/pose_graph_optimizer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "slam/graph/edge_error.h"
#include "slam/graph/graph_initialization.h"
#include "slam/graph/testing/random_graph.h"

namespace slamrig::slam {
namespace {

using ::testing::ElementsAre;

double MaxPositionError(const PoseGraph& graph, const std::vector<Pose2>& truth) {
  double worst = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    worst =
        std::max(worst, (graph.vertices()[i].pose.translation() - truth[i].translation()).norm());
  }
  return worst;
}

// Moves every vertex but the first by a seeded random offset.
void Perturb(PoseGraph* graph, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma);
  for (std::size_t i = 1; i < graph->vertices().size(); ++i) {
    const PoseGraphVertex& v = graph->vertices()[i];
    // Sequenced draws, yaw first (the order these cases were generated in).
    const double yaw = 0.3 * n(rng), y = n(rng), x = n(rng);
    graph->SetPose(v.id, v.pose * Pose2(x, y, yaw));
  }
}

TEST(PoseGraphOptimizerTest, RecoversExactPosesFromExactMeasurements) {
  testing::RandomPoseGraph r =
      testing::MakeRandomPoseGraph({.num_poses = 60, .sigma_xy_m = 0, .sigma_theta_rad = 0});
  Perturb(&r.graph, 0.3, 5);
  ASSERT_GT(MaxPositionError(r.graph, r.truth), 0.5);
  const PoseGraphSummary s = PoseGraphOptimizer({}).Optimize(&r.graph);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_GT(s.initial_chi2, 1.0);
  EXPECT_LT(s.final_chi2, 1e-12);
  EXPECT_LT(MaxPositionError(r.graph, r.truth), 1e-6);
  EXPECT_EQ(s.num_vertices, 60);
  EXPECT_EQ(s.num_edges, static_cast<int>(r.graph.edges().size()));
}

TEST(PoseGraphOptimizerTest, NoisyGraphConvergesNearTruthToALocalMinimum) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph(
      {.num_poses = 80, .loop_closure_probability = 0.5, .sigma_xy_m = 0.02, .seed = 9});
  InitializeFromOdometry(&r.graph);
  const double odometry_error = MaxPositionError(r.graph, r.truth);
  const PoseGraphSummary s = PoseGraphOptimizer({}).Optimize(&r.graph);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_LT(s.final_chi2, s.initial_chi2);
  const double optimised_error = MaxPositionError(r.graph, r.truth);
  EXPECT_LT(optimised_error, 0.15);
  EXPECT_LT(optimised_error, odometry_error);
  // The optimum is at least as good as the truth, and every small move of a vertex costs.
  PoseGraph at_truth = r.graph;
  for (std::size_t i = 0; i < r.truth.size(); ++i)
    at_truth.SetPose(static_cast<int>(i), r.truth[i]);
  EXPECT_LE(s.final_chi2, Chi2(at_truth));
  // chi2 with e ~ N(0, Omega^-1) is about (3 E - 3 (V - 1)) at the optimum: far below 3 E.
  EXPECT_LT(s.final_chi2, 3.0 * s.num_edges);
  for (const int id : {7, 40, 79}) {
    for (int k = 0; k < 3; ++k) {
      PoseGraph moved = r.graph;
      const Pose2& p = moved.pose(id);
      const double d[3] = {k == 0 ? 1e-3 : 0, k == 1 ? 1e-3 : 0, k == 2 ? 1e-3 : 0};
      moved.SetPose(id, Pose2(p.x() + d[0], p.y() + d[1], p.theta() + d[2]));
      EXPECT_GT(Chi2(moved), s.final_chi2) << id << " " << k;
    }
  }
}

TEST(PoseGraphOptimizerTest, AnchorsDoNotMove) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 30, .seed = 4});
  Perturb(&r.graph, 0.2, 8);
  const Pose2 first = r.graph.pose(0);
  PoseGraph fixed = r.graph;
  fixed.SetFixed(10, true);
  fixed.SetFixed(20, true);
  const Pose2 ten = fixed.pose(10), twenty = fixed.pose(20);
  EXPECT_THAT(fixed.AnchorIndices(), ElementsAre(10u, 20u));
  PoseGraphOptimizer({}).Optimize(&r.graph);
  PoseGraphOptimizer({}).Optimize(&fixed);
  EXPECT_EQ(r.graph.pose(0), first);
  EXPECT_EQ(fixed.pose(10), ten);
  EXPECT_EQ(fixed.pose(20), twenty);
  EXPECT_NE(fixed.pose(0), first);
}

TEST(PoseGraphOptimizerTest, SameInputSameBits) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 50, .seed = 2});
  Perturb(&r.graph, 0.2, 3);
  PoseGraph a = r.graph, b = r.graph;
  PoseGraphOptimizer({}).Optimize(&a);
  PoseGraphOptimizer({}).Optimize(&b);
  for (std::size_t i = 0; i < a.vertices().size(); ++i) {
    ASSERT_EQ(a.vertices()[i].pose, b.vertices()[i].pose) << i;
  }
}

TEST(PoseGraphOptimizerTest, RobustLossResistsAFalseLoopClosure) {
  testing::RandomPoseGraph r =
      testing::MakeRandomPoseGraph({.num_poses = 60, .loop_closure_probability = 0.4, .seed = 6});
  PoseGraph clean = r.graph;
  PoseGraphOptimizer({}).Optimize(&clean);
  // A loop closure that claims vertex 50 sits 5 m beside vertex 10.
  r.graph.AddEdge({.from = 10,
                   .to = 50,
                   .measurement = Pose2(5.0, 0.0, 1.0),
                   .information = r.graph.edges()[0].information,
                   .kind = EdgeKind::kLoopClosure});
  PoseGraph plain = r.graph;
  PoseGraphOptimizer({}).Optimize(&plain);
  std::vector<Pose2> clean_poses;
  for (const PoseGraphVertex& v : clean.vertices()) clean_poses.push_back(v.pose);
  // Without a loss the false edge drags the map by metres; a robust loss keeps it within a
  // fifth of that of the clean optimum (Huber: 4 cm, Cauchy: 23 cm on this graph).
  const double plain_error = MaxPositionError(plain, clean_poses);
  EXPECT_GT(plain_error, 1.0);
  for (const RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
    PoseGraph robust = r.graph;
    PoseGraphOptimizerOptions options;
    options.robust_loss = loss;
    const PoseGraphSummary s = PoseGraphOptimizer(options).Optimize(&robust);
    EXPECT_TRUE(s.converged) << s.message;
    EXPECT_LT(MaxPositionError(robust, clean_poses), 0.2 * plain_error) << RobustLossName(loss);
  }
  // Restricted to loop closures, the loss leaves odometry edges quadratic: with every edge
  // robust the result differs.
  PoseGraph loops_only = r.graph, all = r.graph;
  PoseGraphOptimizerOptions options;
  options.robust_loss = RobustLoss::kHuber;
  PoseGraphOptimizer(options).Optimize(&loops_only);
  options.robust_loss_on_all_edges = true;
  PoseGraphOptimizer(options).Optimize(&all);
  EXPECT_NE(loops_only.pose(30), all.pose(30));
}

TEST(PoseGraphOptimizerTest, SwitchableConstraintsTurnOffOnlyTheFalseLoopClosure) {
  testing::RandomPoseGraph r =
      testing::MakeRandomPoseGraph({.num_poses = 60, .loop_closure_probability = 0.4, .seed = 6});
  PoseGraph clean = r.graph;
  PoseGraphOptimizer({}).Optimize(&clean);
  std::vector<Pose2> clean_poses;
  for (const PoseGraphVertex& v : clean.vertices()) clean_poses.push_back(v.pose);
  const std::size_t false_edge = r.graph.edges().size();
  r.graph.AddEdge({.from = 10,
                   .to = 50,
                   .measurement = Pose2(5.0, 0.0, 1.0),
                   .information = r.graph.edges()[0].information,
                   .kind = EdgeKind::kLoopClosure});
  PoseGraphOptimizerOptions options;
  options.robust_loss = RobustLoss::kSwitchable;
  // Half off at a whitened error of 4 (chi2 16, the 3-dof 99.9 % gate): a true closure's chi2 is
  // about 3, so its switch settles near 16 / 19.
  options.robust_loss_scale = 4.0;
  const PoseGraphSummary s = PoseGraphOptimizer(options).Optimize(&r.graph);
  EXPECT_TRUE(s.converged) << s.message;
  ASSERT_EQ(s.switches.size(), r.graph.edges().size());
  // The false closure is off; every true one stays on (its switch at the closed form
  // scale^2 / (s + scale^2) of its small residual), odometry edges have no switch.
  EXPECT_LT(s.switches[false_edge], 0.01);
  int loops = 0;
  for (std::size_t k = 0; k < false_edge; ++k) {
    if (r.graph.edges()[k].kind == EdgeKind::kLoopClosure) {
      ++loops;
      EXPECT_GT(s.switches[k], 0.5) << k;
    } else {
      EXPECT_EQ(s.switches[k], 1.0) << k;
    }
  }
  EXPECT_GT(loops, 5);
  EXPECT_LT(MaxPositionError(r.graph, clean_poses), 0.05);
}

TEST(PoseGraphOptimizerTest, ASwitchSettlesWhereTheClosedFormPutsIt) {
  // Two vertices, a rigid odometry edge and a loop closure that disagrees by 1 m along x with
  // information 4 (whitened error 2): the poses barely move, and the switch minimises
  // w^2 * 4 + scale^2 (1 - w)^2, i.e. w = scale^2 / (4 + scale^2).
  for (const double scale : {0.5, 1.0, 2.0, 4.0}) {
    PoseGraph g;
    g.AddVertex(0, Pose2(), /*fixed=*/true);
    g.AddVertex(1, Pose2(1.0, 0.0, 0.0));
    g.AddEdge({.from = 0,
               .to = 1,
               .measurement = Pose2(1.0, 0.0, 0.0),
               .information = 1e8 * Eigen::Matrix3d::Identity(),
               .kind = EdgeKind::kOdometry});
    g.AddEdge({.from = 0,
               .to = 1,
               .measurement = Pose2(2.0, 0.0, 0.0),
               .information = 4.0 * Eigen::Matrix3d::Identity(),
               .kind = EdgeKind::kLoopClosure});
    PoseGraphOptimizerOptions options;
    options.robust_loss = RobustLoss::kSwitchable;
    options.robust_loss_scale = scale;
    const PoseGraphSummary s = PoseGraphOptimizer(options).Optimize(&g);
    ASSERT_EQ(s.switches.size(), 2u);
    EXPECT_EQ(s.switches[0], 1.0);
    EXPECT_NEAR(s.switches[1], scale * scale / (4.0 + scale * scale), 1e-4) << scale;
  }
}

TEST(PoseGraphOptimizerTest, ReportsAnIterationLimitAsNotConverged) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 60, .seed = 12});
  Perturb(&r.graph, 0.5, 13);
  PoseGraphOptimizerOptions options;
  options.max_iterations = 1;
  const PoseGraphSummary s = PoseGraphOptimizer(options).Optimize(&r.graph);
  EXPECT_FALSE(s.converged);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_FALSE(s.message.empty());
}

TEST(PoseGraphOptimizerTest, DoglegReachesTheSameOptimum) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 60, .seed = 14});
  InitializeFromOdometry(&r.graph);
  PoseGraph lm = r.graph, dogleg = r.graph;
  PoseGraphOptimizerOptions options;
  options.trust_region = TrustRegion::kDogleg;
  const double chi2_lm = PoseGraphOptimizer({}).Optimize(&lm).final_chi2;
  const double chi2_dogleg = PoseGraphOptimizer(options).Optimize(&dogleg).final_chi2;
  EXPECT_NEAR(chi2_dogleg, chi2_lm, 1e-6 * chi2_lm);
}

TEST(PoseGraphOptimizerTest, AutodiffJacobiansReachTheSameOptimum) {
  testing::RandomPoseGraph r = testing::MakeRandomPoseGraph({.num_poses = 60, .seed = 15});
  InitializeFromOdometry(&r.graph);
  PoseGraph analytic = r.graph, autodiff = r.graph;
  PoseGraphOptimizerOptions options;
  options.autodiff_jacobians = true;
  const PoseGraphSummary a = PoseGraphOptimizer({}).Optimize(&analytic);
  const PoseGraphSummary b = PoseGraphOptimizer(options).Optimize(&autodiff);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_NEAR(a.final_chi2, b.final_chi2, 1e-9 * a.final_chi2);
  for (std::size_t i = 0; i < analytic.vertices().size(); ++i) {
    EXPECT_NEAR(analytic.vertices()[i].pose.x(), autodiff.vertices()[i].pose.x(), 1e-9);
    EXPECT_NEAR(analytic.vertices()[i].pose.y(), autodiff.vertices()[i].pose.y(), 1e-9);
  }
}

TEST(PoseGraphOptimizerTest, IncrementalUseEndsAtTheBatchOptimum) {
  // A front end adds one pose and its edges at a time and re-optimises from where it left off.
  const testing::RandomPoseGraph r =
      testing::MakeRandomPoseGraph({.num_poses = 50, .loop_closure_probability = 0.4, .seed = 16});
  PoseGraph online;
  const PoseGraphOptimizer optimizer({});
  online.AddVertex(0, Pose2());
  std::size_t next_edge = 0;
  for (int id = 1; id < 50; ++id) {
    const PoseGraphEdge* odometry = nullptr;
    for (const PoseGraphEdge& e : r.graph.edges()) {
      if (e.kind == EdgeKind::kOdometry && e.to == id) odometry = &e;
    }
    online.AddVertex(id, online.pose(id - 1) * odometry->measurement);
    bool loop_closed = false;
    for (; next_edge < r.graph.edges().size(); ++next_edge) {
      const PoseGraphEdge& e = r.graph.edges()[next_edge];
      if (e.kind == EdgeKind::kOdometry) {
        if (e.to > id) break;
        online.AddEdge(e);
      }
    }
    for (const PoseGraphEdge& e : r.graph.edges()) {
      if (e.kind == EdgeKind::kLoopClosure && e.to == id) {
        online.AddEdge(e);
        loop_closed = true;
      }
    }
    if (loop_closed) optimizer.Optimize(&online);
  }
  optimizer.Optimize(&online);
  PoseGraph batch = r.graph;
  InitializeFromOdometry(&batch);
  const double batch_chi2 = optimizer.Optimize(&batch).final_chi2;
  EXPECT_EQ(online.edges().size(), batch.edges().size());
  EXPECT_NEAR(Chi2(online), batch_chi2, 1e-6 * batch_chi2);
}

TEST(PoseGraphOptimizerTest, EmptyAndEdgelessGraphsAreNoOps) {
  PoseGraph empty;
  EXPECT_TRUE(PoseGraphOptimizer({}).Optimize(&empty).converged);
  PoseGraph lonely;
  lonely.AddVertex(3, Pose2(1, 2, 3));
  lonely.AddVertex(4, Pose2(4, 5, 6));
  const PoseGraphSummary s = PoseGraphOptimizer({}).Optimize(&lonely);
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.final_chi2, 0.0);
  EXPECT_EQ(lonely.pose(4), Pose2(4, 5, 6));
}

TEST(PoseGraphOptimizerOptionsTest, ValidateNamesFieldValueAndRule) {
  PoseGraphOptimizerOptions o;
  EXPECT_TRUE(o.Validate().empty());
  o.max_iterations = 0;
  o.robust_loss_scale = -1.0;
  o.initial_trust_region_radius = 0.0;
  o.num_threads = 0;
  o.function_tolerance = std::nan("");
  EXPECT_THAT(o.Validate(), ElementsAre("max_iterations = 0; must be >= 1",
                                        "robust_loss_scale = -1; must be finite and > 0",
                                        "initial_trust_region_radius = 0; must be finite and > 0",
                                        "num_threads = 0; must be >= 1",
                                        "function_tolerance = nan; must be finite and >= 0"));
}

}  // namespace
}  // namespace slamrig::slam
