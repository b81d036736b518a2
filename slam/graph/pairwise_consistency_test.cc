#include "slam/graph/pairwise_consistency.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

namespace slamrig::slam {
namespace {

// The largest clique by trying every subset (small graphs only).
std::size_t BruteForceCliqueSize(const std::vector<std::vector<bool>>& adjacent) {
  const int n = static_cast<int>(adjacent.size());
  std::size_t best = 0;
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    bool clique = true;
    for (int u = 0; u < n && clique; ++u) {
      for (int w = u + 1; w < n && clique; ++w) {
        if ((mask >> u & 1u) && (mask >> w & 1u) && !adjacent[u][w]) clique = false;
      }
    }
    if (clique)
      best = std::max<std::size_t>(best, static_cast<std::size_t>(__builtin_popcount(mask)));
  }
  return best;
}

TEST(MaximumCliqueTest, MatchesBruteForceOnRandomGraphs) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 13;
    const double density = 0.2 + 0.7 * (trial % 7) / 6.0;
    std::bernoulli_distribution edge(density);
    std::vector<std::vector<bool>> adjacent(n, std::vector<bool>(n, false));
    for (int u = 0; u < n; ++u) {
      for (int w = u + 1; w < n; ++w) adjacent[u][w] = adjacent[w][u] = edge(rng);
    }
    const std::vector<int> clique = MaximumClique(adjacent, 1'000'000);
    ASSERT_EQ(clique.size(), BruteForceCliqueSize(adjacent)) << "trial " << trial;
    ASSERT_TRUE(std::is_sorted(clique.begin(), clique.end()));
    for (std::size_t a = 0; a < clique.size(); ++a) {
      for (std::size_t b = a + 1; b < clique.size(); ++b) {
        ASSERT_TRUE(adjacent[clique[a]][clique[b]]) << "trial " << trial;
      }
    }
  }
}

TEST(OdometryChainTest, StretchVarianceSumsEdgesWithTheirLevers) {
  OdometryChain chain;
  chain.Append(Pose2(1.0, 0.0, 0.0), 0.01, 0.001);
  chain.Append(Pose2(1.0, 0.0, M_PI / 2), 0.02, 0.002);
  chain.Append(Pose2(1.0, 0.0, 0.0), 0.03, 0.003);
  // Nodes at (0,0), (1,0), (2,0), (2,1). Stretch 1..3 about the end (5, 1): edges 2 and 3.
  const Eigen::Vector2d end(5.0, 1.0);
  const Eigen::Vector2d v = chain.StretchVariance(3, 1, end);
  const double expected_xy = 0.02 + 0.03 + 0.002 * (Eigen::Vector2d(2, 0) - end).squaredNorm() +
                             0.003 * (Eigen::Vector2d(2, 1) - end).squaredNorm();
  EXPECT_NEAR(v.x(), expected_xy, 1e-12);
  EXPECT_NEAR(v.y(), 0.005, 1e-15);
  EXPECT_NEAR(chain.pose(3).x(), 2.0, 1e-12);
  EXPECT_NEAR(chain.pose(3).y(), 1.0, 1e-12);
}

Pose2 Noisy(const Pose2& p, double sigma_xy, double sigma_yaw, std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  // Sequenced draws, yaw first (the order these cases were generated in).
  const double yaw = sigma_yaw * n(*rng), y = sigma_xy * n(*rng), x = sigma_xy * n(*rng);
  return p * Pose2(x, y, yaw);
}

// Two identical rooms 8 m apart: two laps of a circle in room A, a walk to room B, two laps
// there. True closures join each second lap to the first in the same room; the aliased ones join
// room B's nodes to the matching places in room A (as a scan matcher would, the rooms looking the
// same) and agree with each other; a few are outright wrong. Only the true ones may be kept.
TEST(PairwiseConsistencyTest, KeepsTheTrueClosuresOfAnAliasedGraph) {
  constexpr int kLap = 24;
  constexpr double kRadius = 1.5;
  std::vector<Pose2> truth;
  auto circle = [&](double cx) {
    for (int lap = 0; lap < 2; ++lap) {
      for (int k = 0; k < kLap; ++k) {
        const double a = 2.0 * M_PI * k / kLap;
        truth.emplace_back(cx + kRadius * std::cos(a), kRadius * std::sin(a), a + M_PI / 2);
      }
    }
  };
  circle(0.0);
  const int room_b = static_cast<int>(truth.size()) + 8;
  for (int k = 1; k <= 8; ++k) truth.emplace_back(kRadius + k, 0.0, 0.0);  // along y = 0
  circle(8.0);

  std::mt19937 rng(3);
  constexpr double kOdomXy = 0.01, kOdomYaw = 0.004, kLoopXy = 0.02, kLoopYaw = 0.005;
  OdometryChain chain;
  for (std::size_t k = 1; k < truth.size(); ++k) {
    chain.Append(Noisy(truth[k - 1].Between(truth[k]), kOdomXy, kOdomYaw, &rng), kOdomXy * kOdomXy,
                 kOdomYaw * kOdomYaw);
  }
  const Eigen::Matrix3d loop_covariance =
      Eigen::Vector3d(kLoopXy * kLoopXy, kLoopXy * kLoopXy, kLoopYaw * kLoopYaw).asDiagonal();
  struct Labelled {
    ClosureHypothesis h;
    bool truth;
  };
  std::vector<Labelled> all;
  const Pose2 a_from_b(-8.0, 0.0, 0.0);  // where room B's places look like they are
  for (int k = 0; k < kLap; ++k) {
    all.push_back({{k, kLap + k, Noisy(truth[k].Between(truth[kLap + k]), kLoopXy, kLoopYaw, &rng),
                    loop_covariance},
                   true});
    const int b1 = room_b + k, b2 = room_b + kLap + k;
    all.push_back(
        {{b1, b2, Noisy(truth[b1].Between(truth[b2]), kLoopXy, kLoopYaw, &rng), loop_covariance},
         true});
    if (k % 2 == 0) {  // room B's second lap matched to room A's first lap
      const Pose2 aliased = truth[k].Between(a_from_b * truth[b2]);
      all.push_back({{k, b2, Noisy(aliased, kLoopXy, kLoopYaw, &rng), loop_covariance}, false});
    }
    if (k % 6 == 0) {  // a wrong match, 0.6 m and 0.3 rad off
      const Pose2 wrong = truth[k].Between(truth[kLap + k]) * Pose2(0.6, 0.0, 0.3);
      all.push_back({{k, kLap + k, wrong, loop_covariance}, false});
    }
  }
  // In the order a front end finds them: by their newer node.
  std::stable_sort(all.begin(), all.end(),
                   [](const Labelled& a, const Labelled& b) { return a.h.to < b.h.to; });

  PairwiseConsistency consistency(16.27);
  for (const Labelled& l : all) consistency.Add(l.h, chain);
  std::set<int> kept(consistency.kept().begin(), consistency.kept().end());
  int true_kept = 0, true_total = 0;
  for (int i = 0; i < static_cast<int>(all.size()); ++i) {
    if (all[i].truth) {
      ++true_total;
      true_kept += static_cast<int>(kept.count(i));
    } else {
      EXPECT_EQ(kept.count(i), 0u) << "false closure " << all[i].h.from << " -> " << all[i].h.to;
    }
  }
  EXPECT_GE(true_kept, static_cast<int>(0.95 * true_total)) << true_kept << " of " << true_total;
  // The aliased closures agree among themselves (they would fool a single-closure test); the
  // odometry between the rooms is what refutes them.
  std::vector<int> aliased;
  for (int i = 0; i < static_cast<int>(all.size()); ++i) {
    if (!all[i].truth && all[i].h.to >= room_b) aliased.push_back(i);
  }
  ASSERT_GE(aliased.size(), 2u);
  EXPECT_TRUE(consistency.consistent(aliased[0], aliased[1]));
}

TEST(PairwiseCycleChi2Test, SmallForAConsistentPairLargeWhenOneIsShifted) {
  OdometryChain chain;
  for (int k = 0; k < 20; ++k) chain.Append(Pose2(0.5, 0.0, 0.1), 1e-4, 1e-5);
  const Eigen::Matrix3d covariance = Eigen::Vector3d(4e-4, 4e-4, 2.5e-5).asDiagonal();
  const ClosureHypothesis a{2, 15, chain.pose(2).Between(chain.pose(15)), covariance};
  const ClosureHypothesis b{4, 18, chain.pose(4).Between(chain.pose(18)), covariance};
  EXPECT_NEAR(PairwiseCycleChi2(a, b, chain), 0.0, 1e-9);
  ClosureHypothesis shifted = b;
  shifted.measurement = b.measurement * Pose2(0.5, 0.0, 0.0);
  EXPECT_GT(PairwiseCycleChi2(a, shifted, chain), 50.0);
  EXPECT_NEAR(PairwiseCycleChi2(a, shifted, chain), PairwiseCycleChi2(shifted, a, chain),
              0.5 * PairwiseCycleChi2(a, shifted, chain));
}

}  // namespace
}  // namespace slamrig::slam
