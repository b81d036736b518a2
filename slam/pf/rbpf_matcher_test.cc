#include "slam/pf/rbpf_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace slamrig::slam {
namespace {

// Two or three draws of `u` as a vector, the last coordinate drawn first: sequenced (the
// arguments of one call are drawn in the compiler's order), in the order the cases here were
// generated with.
Eigen::Vector2d Draw2(std::mt19937& rng, std::uniform_real_distribution<double>& u) {
  const double y = u(rng);
  return {u(rng), y};
}
Eigen::Vector3d Draw3(std::mt19937& rng, std::uniform_real_distribution<double>& u) {
  const double z = u(rng);
  const double y = u(rng);
  return {u(rng), y, z};
}

// A room 6 m x 4 m seen from inside: a scan of its walls and a TiledGrid built from it.
LaserScan RoomScan(const Pose2& world_from_base) {
  LaserScan scan;
  scan.angle_min_rad = -3.1;
  scan.angle_increment_rad = 6.2 / 360;
  scan.range_min_m = 0.1;
  scan.range_max_m = 20.0;
  for (int i = 0; i < 360; ++i) {
    const double a = world_from_base.theta() + scan.angle_min_rad + i * scan.angle_increment_rad;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    const Eigen::Vector2d o = world_from_base.translation();
    // Walls x = -3, x = 3, y = -2, y = 2.
    double r = 1e9;
    if (d.x() > 1e-9) r = std::min(r, (3.0 - o.x()) / d.x());
    if (d.x() < -1e-9) r = std::min(r, (-3.0 - o.x()) / d.x());
    if (d.y() > 1e-9) r = std::min(r, (2.0 - o.y()) / d.y());
    if (d.y() < -1e-9) r = std::min(r, (-2.0 - o.y()) / d.y());
    scan.ranges_m.push_back(static_cast<float>(r));
  }
  return scan;
}

TEST(RbpfMatcherTest, ClimbRecoversRandomOffsetsWithinReach) {
  OccupancyGridOptions map_options;
  TiledGrid map(map_options);
  const Pose2 truth(0.3, -0.2, 0.1);
  // The map from a few nearby poses, as a filter would build it.
  for (const Pose2& p : {Pose2(0, 0, 0), Pose2(0.5, 0.3, 0.4), Pose2(-0.6, -0.4, -0.3)}) {
    map.InsertScan(RoomScan(p), p);
  }
  const LaserScan scan = RoomScan(truth);
  const std::vector<MatchPoint> points =
      MakeMatchPoints(scan, ScanPointsOptions{0.1, 30.0, 1, 0.0}, map_options.resolution_m);
  ASSERT_GT(points.size(), 300u);
  const RbpfMatcher matcher(RbpfMatcherOptions{});
  // Grazing beams find their wall's cells behind them along the beam (the free-cell test rejects
  // those), so not every point matches even at the truth; far off, few do.
  const int matched = matcher.Evaluate(map, points, truth).matched;
  EXPECT_GT(matched, static_cast<int>(points.size()) / 2);
  EXPECT_LT(matcher.Evaluate(map, points, Pose2(0.5, 0.0, 0.1)).matched, matched / 4);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d d = Draw3(rng, u);
    const Pose2 start(truth.x() + 0.06 * d.x(), truth.y() + 0.06 * d.y(),
                      truth.theta() + 0.03 * d.z());
    const ClimbResult r = matcher.Climb(map, points, start, PosePrior{start, 1.0, 1.0});
    EXPECT_NEAR(r.pose.x(), truth.x(), 0.025) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.025) << trial;
    EXPECT_NEAR(r.pose.theta(), truth.theta(), 0.015) << trial;
    EXPECT_GE(r.fit.score, matcher.Evaluate(map, points, start).score);
  }
}

// A wall cell counts only when its counterpart one cell back along the beam is not occupied: a
// point reaching a two-cell-thick wall from behind matches the back cell, not the front one.
// With the map's hit means the scan that built the map fits it closer than with the cells'
// centres: every point is compared with where it (and its cell's other hits) fell, not with the
// lattice. The walls sit at x = +-3, y = +-2, so the hits of the wall x = 3 land on either side
// of a cell edge and a centre is 2.5 cm from them.
TEST(RbpfMatcherTest, HitMeansBringTheWallsOffTheLattice) {
  OccupancyGridOptions map_options;
  const Pose2 pose(0.3, -0.2, 0.1);
  const LaserScan scan = RoomScan(pose);
  TiledGrid centres(map_options);
  TiledGrid means(map_options);
  means.RecordHitMeans(true);
  centres.InsertScan(scan, pose);
  means.InsertScan(scan, pose);
  const std::vector<MatchPoint> points =
      MakeMatchPoints(scan, ScanPointsOptions{0.1, 30.0, 1, 0.0}, map_options.resolution_m);
  const RbpfMatcher matcher(RbpfMatcherOptions{});
  const MatchFit with_centres = matcher.Evaluate(centres, points, pose);
  const MatchFit with_means = matcher.Evaluate(means, points, pose);
  EXPECT_EQ(with_means.matched, with_centres.matched);
  ASSERT_GT(with_means.matched, static_cast<int>(points.size()) / 2);
  // The matched points' part of the log-likelihood (each unmatched one adds no_match, -2): with
  // the centres a point costs on average more than (2.5 cm)^2 / (2 (5 cm)^2) = 0.125 (the
  // distance across the wall's cell edge and along the wall); with the means less than half that.
  auto matched_part = [&](const MatchFit& fit) {
    return fit.log_likelihood - RbpfMatcherOptions{}.no_match_log_likelihood *
                                    static_cast<double>(points.size() - fit.matched);
  };
  EXPECT_LT(matched_part(with_centres), -0.125 * with_centres.matched);
  EXPECT_GT(matched_part(with_means), 0.5 * matched_part(with_centres));
  EXPECT_GT(with_means.score, with_centres.score);
}

TEST(RbpfMatcherTest, MatchesWallsOnlyFromTheSideTheBeamCameFrom) {
  OccupancyGridOptions map_options;  // 0.05 m cells
  TiledGrid map(map_options);
  for (int iy = -10; iy <= 10; ++iy) {
    map.Update({40, iy}, 2.0f);  // x in [2.00, 2.05)
    map.Update({41, iy}, 2.0f);  // x in [2.05, 2.10)
    map.Update({39, iy}, -2.0f);
  }
  const RbpfMatcherOptions options;
  const RbpfMatcher matcher(options);
  const Eigen::Vector2d hit(2.02, 0.026);
  // From the front (free point in cell 39): the nearest cell, 40, at 5 mm.
  const std::vector<MatchPoint> front = {{hit, {1.97, 0.026}}};
  const MatchFit f = matcher.Evaluate(map, front, Pose2());
  EXPECT_EQ(f.matched, 1);
  EXPECT_NEAR(f.score, std::exp(-0.5 * (0.005 * 0.005 + 0.001 * 0.001) / (0.05 * 0.05)), 0.01);
  // From behind (free point in cell 41, occupied): cell 40 is rejected, cell 41 is 55 mm away.
  const std::vector<MatchPoint> back = {{hit, {2.07, 0.026}}};
  const MatchFit b = matcher.Evaluate(map, back, Pose2());
  EXPECT_EQ(b.matched, 1);
  EXPECT_NEAR(b.score, std::exp(-0.5 * (0.055 * 0.055 + 0.001 * 0.001) / (0.05 * 0.05)), 0.01);
  EXPECT_NEAR(b.log_likelihood,
              std::max(-0.5 * (0.055 * 0.055 + 0.001 * 0.001) / (0.05 * 0.05),
                       options.no_match_log_likelihood),
              1e-9);
  // No wall within the kernel: no match, no_match_log_likelihood.
  const std::vector<MatchPoint> far = {{{5.0, 0.0}, {4.95, 0.0}}};
  const MatchFit none = matcher.Evaluate(map, far, Pose2());
  EXPECT_EQ(none.matched, 0);
  EXPECT_DOUBLE_EQ(none.log_likelihood, options.no_match_log_likelihood);
}

// The rule of CountIndependentPoints, without its hashing: in order, keep a point at least
// `length` from every kept one.
int BruteForceIndependent(const std::vector<MatchPoint>& points, double length) {
  std::vector<Eigen::Vector2d> kept;
  for (const MatchPoint& p : points) {
    bool near = false;
    for (const Eigen::Vector2d& q : kept) near = near || (q - p.hit).norm() < length;
    if (!near) kept.push_back(p.hit);
  }
  return static_cast<int>(kept.size());
}

// Dense beams along one straight wall: along a line the rule keeps the first point at least
// `length` past the last kept one, so the count is 1 + floor(l / (m d)) with m = ceil(length / d)
// points between kept ones, about l / length + 1, whatever the wall's direction and place.
TEST(RbpfMatcherTest, DenseWallPointsCountAsWallLengthOverCorrelationLength) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double length = 0.1 + 0.1 * (u(rng) + 1.0);  // 0.1 - 0.3 m
    const double spacing = 0.013 + 0.005 * u(rng);
    const int n = 60 + static_cast<int>(100 * (u(rng) + 1.0));
    const double a = 3.2 * u(rng);
    const Eigen::Vector2d start = 5.0 * Draw2(rng, u);
    const Eigen::Vector2d dir(std::cos(a), std::sin(a));
    std::vector<MatchPoint> points;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d hit = start + i * spacing * dir;
      points.push_back({hit, hit});
    }
    const double wall = (n - 1) * spacing;
    // The first multiple of the spacing at or beyond `length` (away from rounding edges).
    const int step = static_cast<int>(std::ceil(length / spacing - 1e-9));
    const int expected = 1 + (n - 1) / step;
    EXPECT_EQ(CountIndependentPoints(points, length), expected) << trial;
    EXPECT_NEAR(CountIndependentPoints(points, length), wall / length + 1.0,
                wall / length * spacing / length + 1.0)
        << trial;
  }
}

TEST(RbpfMatcherTest, ScatteredPointsFartherApartThanTheLengthCountOneEach) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  const double length = 0.1;
  std::vector<MatchPoint> points;
  while (points.size() < 40) {
    const Eigen::Vector2d p = Draw2(rng, u);
    bool near = false;
    for (const MatchPoint& q : points) near = near || (q.hit - p).norm() < 1.5 * length;
    if (!near) points.push_back({p, p});
  }
  EXPECT_EQ(CountIndependentPoints(points, length), 40);
  EXPECT_EQ(CountIndependentPoints(points, 0.0), 40);
  EXPECT_EQ(CountIndependentPoints({}, length), 0);
  // All in one spot: one piece of evidence.
  std::vector<MatchPoint> pile(25, MatchPoint{{1.0, 2.0}, {1.0, 2.0}});
  EXPECT_EQ(CountIndependentPoints(pile, length), 1);
}

// Random clusters of points, against the rule computed pair by pair, and the same after a rigid
// motion of the whole scan.
TEST(RbpfMatcherTest, IndependentCountMatchesThePairwiseRuleAndIgnoresRigidMotion) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    const double length = 0.05 + 0.1 * (u(rng) + 1.0);
    std::vector<MatchPoint> points;
    const int clusters = 1 + trial % 7;
    for (int c = 0; c < clusters; ++c) {
      const Eigen::Vector2d centre = 4.0 * Draw2(rng, u);
      const double spread = 0.5 * (u(rng) + 1.0);
      for (int i = 0; i < 40; ++i) {
        const Eigen::Vector2d p = centre + spread * Draw2(rng, u);
        points.push_back({p, p});
      }
    }
    const int count = CountIndependentPoints(points, length);
    EXPECT_EQ(count, BruteForceIndependent(points, length)) << trial;
    const Eigen::Vector3d m = Draw3(rng, u);
    const Pose2 motion(10.0 * m.x(), 10.0 * m.y(), 3.1 * m.z());
    std::vector<MatchPoint> moved;
    for (const MatchPoint& p : points) {
      const Eigen::Vector2d q = motion * p.hit;
      moved.push_back({q, q});
    }
    EXPECT_EQ(CountIndependentPoints(moved, length), count) << trial;
  }
}

// AssignIndependenceWeights against the rule computed pair by pair (1 / the points closer than the
// length, itself included), on random clusters, and the same weights after a rigid motion.
TEST(RbpfMatcherTest, IndependenceWeightsMatchThePairwiseRuleAndIgnoreRigidMotion) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    const double length = 0.05 + 0.1 * (u(rng) + 1.0);
    std::vector<MatchPoint> points;
    for (int c = 0; c < 1 + trial % 5; ++c) {
      const Eigen::Vector2d centre = 4.0 * Draw2(rng, u);
      const double spread = 0.5 * (u(rng) + 1.0);
      for (int i = 0; i < 30; ++i) {
        const Eigen::Vector2d p = centre + spread * Draw2(rng, u);
        points.push_back({p, p});
      }
    }
    AssignIndependenceWeights(points, length);
    const Eigen::Vector3d m = Draw3(rng, u);
    const Pose2 motion(10.0 * m.x(), 10.0 * m.y(), 3.1 * m.z());
    std::vector<MatchPoint> moved;
    for (const MatchPoint& p : points) moved.push_back({motion * p.hit, motion * p.free});
    AssignIndependenceWeights(moved, length);
    for (std::size_t i = 0; i < points.size(); ++i) {
      int near = 0;
      for (const MatchPoint& q : points) near += (q.hit - points[i].hit).norm() < length;
      EXPECT_DOUBLE_EQ(points[i].weight, 1.0 / near) << trial << " " << i;
      EXPECT_DOUBLE_EQ(moved[i].weight, points[i].weight) << trial << " " << i;
    }
  }
}

// A pile of n points in one spot is one piece of evidence in total; isolated points count one
// each; a dense wall's points share theirs with the 2 m neighbours within the length (m = the
// spacings shorter than it), its ends with fewer; length 0 leaves every weight at 1.
TEST(RbpfMatcherTest, IndependenceWeightsSplitOnePieceOfEvidenceAmongNeighbours) {
  std::vector<MatchPoint> pile(25, MatchPoint{{1.0, 2.0}, {1.0, 2.0}});
  AssignIndependenceWeights(pile, 0.1);
  for (const MatchPoint& p : pile) EXPECT_DOUBLE_EQ(p.weight, 1.0 / 25.0);

  std::vector<MatchPoint> mixed;
  for (int i = 0; i < 101; ++i) {
    const Eigen::Vector2d p(0.013 * i, 1.0);  // a wall 1.3 m long, 13 mm spacing
    mixed.push_back({p, p});
  }
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector2d p(0.5 * i, 5.0 + 0.3 * i);  // far, 0.5 m apart
    mixed.push_back({p, p});
  }
  const double length = 0.1;
  AssignIndependenceWeights(mixed, length);
  const int m = 7;  // 7 * 0.013 = 0.091 < 0.1 < 0.104
  EXPECT_DOUBLE_EQ(mixed[50].weight, 1.0 / (2 * m + 1));
  EXPECT_DOUBLE_EQ(mixed[0].weight, 1.0 / (m + 1));
  EXPECT_DOUBLE_EQ(mixed[3].weight, 1.0 / (m + 4));
  for (int i = 101; i < 111; ++i) EXPECT_DOUBLE_EQ(mixed[static_cast<std::size_t>(i)].weight, 1.0);
  // The wall's total: 87 interior points at 1 / (2 m + 1), and at each end 1 / (m + 1) ... 1 / 2 m.
  double wall = 0.0;
  for (int i = 0; i < 101; ++i) wall += mixed[static_cast<std::size_t>(i)].weight;
  double ends = 0.0;
  for (int k = m + 1; k <= 2 * m; ++k) ends += 1.0 / k;
  EXPECT_NEAR(wall, 87.0 / (2 * m + 1) + 2.0 * ends, 1e-9);

  AssignIndependenceWeights(mixed, 0.0);
  for (const MatchPoint& p : mixed) EXPECT_EQ(p.weight, 1.0);
}

// The weighted log-likelihood is the sum of each point's own log-likelihood (the fit of that point
// alone) times its weight; with every weight 1 it is the plain log-likelihood.
TEST(RbpfMatcherTest, WeightedLogLikelihoodSumsEachPointsOwnTimesItsWeight) {
  OccupancyGridOptions map_options;
  TiledGrid map(map_options);
  map.InsertScan(RoomScan(Pose2()), Pose2());
  const ScanPointsOptions points_options{0.1, 30.0, 1, 0.05};
  std::vector<MatchPoint> points =
      MakeMatchPoints(RoomScan(Pose2(0.1, 0.05, 0.02)), points_options, map.resolution());
  ASSERT_GT(points.size(), 50u);
  const RbpfMatcher matcher{RbpfMatcherOptions{}};
  const Pose2 pose(0.08, 0.06, 0.015);  // near, not at, the truth: the points' fits differ
  const MatchFit unit = matcher.Evaluate(map, points, pose);
  EXPECT_DOUBLE_EQ(unit.weighted_log_likelihood, unit.log_likelihood);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double expected = 0.0;
  for (MatchPoint& p : points) {
    p.weight = u(rng);
    expected += p.weight * matcher.Evaluate(map, std::span(&p, 1), pose).log_likelihood;
  }
  const MatchFit weighted = matcher.Evaluate(map, points, pose);
  EXPECT_NEAR(weighted.weighted_log_likelihood, expected, 1e-9 * std::abs(expected));
  EXPECT_DOUBLE_EQ(weighted.log_likelihood, unit.log_likelihood);
  EXPECT_LT(weighted.weighted_log_likelihood, 0.0);
  EXPECT_GT(weighted.weighted_log_likelihood, weighted.log_likelihood);
}

}  // namespace
}  // namespace slamrig::slam
