#include "slam/graph/odometry_release.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "slam/graph/edge_error.h"

namespace slamrig::slam {
namespace {

constexpr int kLap = 24;  // nodes per lap of a circle of radius 4 m
constexpr double kSigmaXy = 0.02;
constexpr double kSigmaYaw = 0.005;

Pose2 Truth(int node) {
  const double a = 2.0 * std::numbers::pi * (node % kLap) / kLap;
  return Pose2(4.0 * std::cos(a), 4.0 * std::sin(a), a + std::numbers::pi / 2);
}

Eigen::Matrix3d Information() {
  return Eigen::Vector3d(1.0 / (kSigmaXy * kSigmaXy), 1.0 / (kSigmaXy * kSigmaXy),
                         1.0 / (kSigmaYaw * kSigmaYaw))
      .asDiagonal();
}

// Two laps of the circle: odometry edges between consecutive nodes, a loop closure from each
// node of the second lap to its twin on the first, every measurement with noise of a tenth of
// its stated sigma. `wrong_odometry` (an edge's `from` node, or -1) is moved 1 m sideways,
// `wrong_closure` (a second-lap node, or -1) 1 m along. The poses start at the odometry's
// composition, and the graph is solved as the back end solves it.
struct TwoLaps {
  PoseGraph graph;
  std::size_t wrong_edge = 0;
};

PoseGraphOptimizerOptions BackEnd() {
  return {.max_iterations = 50, .robust_loss = RobustLoss::kCauchy, .robust_loss_scale = 1.0};
}

// The release's defaults around the back end's solve.
OdometryReleaseOptions ReleaseOptions() {
  OdometryReleaseOptions options;
  options.optimizer = BackEnd();
  return options;
}

TwoLaps MakeTwoLaps(int wrong_odometry, int wrong_closure, std::uint64_t seed,
                    int second_wrong_odometry = -1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 0.1);
  auto noisy = [&](const Pose2& p) {
    const double x = n(rng) * kSigmaXy;
    const double y = n(rng) * kSigmaXy;
    const double yaw = n(rng) * kSigmaYaw;
    return p * Pose2(x, y, yaw);
  };
  TwoLaps laps;
  laps.graph.AddVertex(0, Truth(0), /*fixed=*/true);
  for (int i = 1; i < 2 * kLap; ++i) {
    Pose2 relative = noisy(Truth(i - 1).Between(Truth(i)));
    if (i - 1 == second_wrong_odometry) relative = relative * Pose2(0.0, -0.7, 0.0);
    if (i - 1 == wrong_odometry) {
      relative = relative * Pose2(0.0, 1.0, 0.0);
      laps.wrong_edge = laps.graph.edges().size();
    }
    laps.graph.AddVertex(i, laps.graph.pose(i - 1) * relative);
    laps.graph.AddEdge({i - 1, i, relative, Information(), EdgeKind::kOdometry});
  }
  for (int i = kLap; i < 2 * kLap; ++i) {
    Pose2 relative = noisy(Pose2());
    if (i == wrong_closure) relative = relative * Pose2(1.0, 0.0, 0.0);
    laps.graph.AddEdge({i - kLap, i, relative, Information(), EdgeKind::kLoopClosure});
  }
  PoseGraphOptimizer(BackEnd()).Optimize(&laps.graph);
  return laps;
}

double MaxPositionError(const PoseGraph& graph) {
  double worst = 0.0;
  for (const PoseGraphVertex& v : graph.vertices()) {
    worst = std::max(worst, (v.pose.translation() - Truth(v.id).translation()).norm());
  }
  return worst;
}

auto Any = [](std::size_t) { return true; };
auto Anywhere = [](std::size_t, const Pose2&) { return true; };

TEST(OdometryReleaseTest, FindsTheOneWrongOdometryEdgeWhereverItIs) {
  const OdometryReleaseOptions options = ReleaseOptions();
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 12; ++trial) {
    const int wrong = std::uniform_int_distribution<int>(kLap + 2, 2 * kLap - 5)(rng);
    TwoLaps laps = MakeTwoLaps(wrong, -1, 100 + trial);
    // The back end alone keeps the wrong edge and gives the closures up.
    ASSERT_GE(CountStrainedClosures(laps.graph), 2) << "edge from " << wrong;
    ASSERT_GT(MaxPositionError(laps.graph), 0.5) << "edge from " << wrong;
    const std::optional<OdometryRelease> release =
        ReleaseWrongOdometryEdge(&laps.graph, options, Any, Anywhere);
    ASSERT_TRUE(release.has_value()) << "edge from " << wrong;
    EXPECT_EQ(release->edge, laps.wrong_edge) << "edge from " << wrong;
    EXPECT_EQ(release->strained_after, 0);
    EXPECT_EQ(CountStrainedClosures(laps.graph), 0);
    EXPECT_LT(MaxPositionError(laps.graph), 0.02) << "edge from " << wrong;
  }
}

TEST(OdometryReleaseTest, ReleasesTwoWrongEdgesOneCallAtATime) {
  const OdometryReleaseOptions options = ReleaseOptions();
  TwoLaps laps = MakeTwoLaps(kLap + 6, -1, 21, /*second_wrong_odometry=*/kLap + 15);
  int released = 0;
  while (ReleaseWrongOdometryEdge(&laps.graph, options, Any, Anywhere)) ++released;
  EXPECT_EQ(released, 2);
  EXPECT_EQ(CountStrainedClosures(laps.graph), 0);
  EXPECT_LT(MaxPositionError(laps.graph), 0.02);
}

TEST(OdometryReleaseTest, AnEdgeNotEligibleIsNotReleased) {
  const OdometryReleaseOptions options = ReleaseOptions();
  TwoLaps laps = MakeTwoLaps(kLap + 10, -1, 3);
  const PoseGraph before = laps.graph;
  const std::size_t wrong = laps.wrong_edge;
  const std::optional<OdometryRelease> release = ReleaseWrongOdometryEdge(
      &laps.graph, options, [wrong](std::size_t k) { return k != wrong; }, Anywhere);
  // Any other edge released reconciles fewer closures than needed, or none is tried.
  if (release) {
    EXPECT_NE(release->edge, wrong);
  } else {
    EXPECT_EQ(Chi2(laps.graph), Chi2(before));
  }
}

TEST(OdometryReleaseTest, NoReleaseTheRobotsOwnMotionRulesOut) {
  const OdometryReleaseOptions options = ReleaseOptions();
  TwoLaps laps = MakeTwoLaps(kLap + 10, -1, 3);
  const PoseGraph before = laps.graph;
  const std::size_t wrong = laps.wrong_edge;
  const Pose2 truth = Truth(kLap + 10).Between(Truth(kLap + 11));
  std::vector<std::size_t> asked;
  auto never = [&](std::size_t k, const Pose2& relative) {
    asked.push_back(k);
    // The release gives the wrong edge its true relative pose back.
    if (k == wrong) {
      EXPECT_LT((relative.translation() - truth.translation()).norm(), 0.02);
    }
    return false;
  };
  EXPECT_FALSE(ReleaseWrongOdometryEdge(&laps.graph, options, Any, never).has_value());
  ASSERT_FALSE(asked.empty());
  EXPECT_EQ(asked.front(), wrong);
  EXPECT_EQ(Chi2(laps.graph), Chi2(before));
}

TEST(OdometryReleaseTest, NeverTradesASingleStrainedClosureForAnEdge) {
  const OdometryReleaseOptions options = ReleaseOptions();
  for (int node = kLap + 1; node < 2 * kLap; node += 5) {
    TwoLaps laps = MakeTwoLaps(-1, node, 11);
    ASSERT_EQ(CountStrainedClosures(laps.graph), 1) << "closure at " << node;
    const PoseGraph before = laps.graph;
    EXPECT_FALSE(ReleaseWrongOdometryEdge(&laps.graph, options, Any, Anywhere).has_value());
    for (std::size_t i = 0; i < before.vertices().size(); ++i) {
      EXPECT_EQ(laps.graph.vertices()[i].pose.x(), before.vertices()[i].pose.x());
    }
  }
}

TEST(OdometryReleaseTest, LeavesAConsistentGraphAlone) {
  const OdometryReleaseOptions options = ReleaseOptions();
  TwoLaps laps = MakeTwoLaps(-1, -1, 5);
  EXPECT_EQ(CountStrainedClosures(laps.graph), 0);
  EXPECT_FALSE(ReleaseWrongOdometryEdge(&laps.graph, options, Any, Anywhere).has_value());
  EXPECT_LT(MaxPositionError(laps.graph), 0.02);
}

}  // namespace
}  // namespace slamrig::slam
