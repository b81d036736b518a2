#include "slam/matching/icp_matcher.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <thread>
#include <utility>
#include <vector>

#include "slam/matching/testing/segment_world.h"
#include "slam/odometry/gaussian.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

// A random pose in the office's lower corridor, clear of walls and pillars. The draws are
// sequenced (arguments of one call would be drawn in the compiler's order), theta first.
Pose2 RandomCorridorPose(RandomEngine& rng) {
  const double theta = 6.28 * Uniform01(rng);
  const double y = 1.4 + 1.2 * Uniform01(rng);
  const double x = 2.0 + 15.5 * Uniform01(rng);
  return Pose2(x, y, theta);
}

Pose2 RandomOffset(RandomEngine& rng, double xy_m, double yaw_rad) {
  const double theta = yaw_rad * (2.0 * Uniform01(rng) - 1.0);
  const double y = xy_m * (2.0 * Uniform01(rng) - 1.0);
  const double x = xy_m * (2.0 * Uniform01(rng) - 1.0);
  return Pose2(x, y, theta);
}

double YawError(const Pose2& a, const Pose2& b) {
  return std::abs(NormalizeAngle(a.theta() - b.theta()));
}

class IcpRecoveryTest : public ::testing::TestWithParam<IcpMetric> {};

// Scan-to-scan: two noisy scans a random offset apart (a few cm and degrees) are aligned from
// the identity guess to well below the offset. Point-to-point is limited by the sampling (the
// two scans' points are not the same wall points), point-to-line by the range noise.
TEST_P(IcpRecoveryTest, RecoversRandomOffsetsBetweenScans) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(7);
  IcpOptions options;
  options.metric = GetParam();
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  const RangeFinderSpec spec;
  const bool to_line = GetParam() == IcpMetric::kPointToLine;
  const double xy_tolerance = to_line ? 0.01 : 0.02, yaw_tolerance = to_line ? 0.003 : 0.008;
  int converged = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Pose2 a = RandomCorridorPose(rng);
    const Pose2 offset = RandomOffset(rng, 0.08, 0.06);
    const LaserScan ref = world.Scan(a, Time(), spec, &rng);
    const LaserScan src = world.Scan(a * offset, Time(), spec, &rng);
    const std::optional<MatchResult> m = IcpMatcher::MatchScans(options, points, ref, src, Pose2());
    ASSERT_TRUE(m.has_value()) << trial;
    EXPECT_LT((m->pose.translation() - offset.translation()).norm(), xy_tolerance) << trial;
    EXPECT_LT(YawError(m->pose, offset), yaw_tolerance) << trial;
    EXPECT_GT(m->score, 0.8) << trial;
    converged += m->converged ? 1 : 0;
  }
  EXPECT_GE(converged, 36);  // the rest hit the cap oscillating between near-equal pairings
}

INSTANTIATE_TEST_SUITE_P(Metrics, IcpRecoveryTest,
                         ::testing::Values(IcpMetric::kPointToPoint, IcpMetric::kPointToLine));

// Scan-to-point-set: a local map made of two scans from other poses, in the world frame.
TEST(IcpMatcherTest, AlignsAScanToALocalMapOfOtherScans) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(3);
  const RangeFinderSpec spec;
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose2 truth = RandomCorridorPose(rng);
    std::vector<Eigen::Vector2d> map;
    for (const Pose2& key : {truth * Pose2(-0.5, 0.1, 0.2), truth * Pose2(-1.0, -0.1, -0.1)}) {
      for (const Eigen::Vector2d& p :
           ScanToBasePoints(world.Scan(key, Time(), spec, &rng), points)) {
        map.push_back(key * p);
      }
    }
    const IcpMatcher matcher(IcpOptions{}, std::move(map));
    const std::vector<Eigen::Vector2d> scan =
        ScanToBasePoints(world.Scan(truth, Time(), spec, &rng), points);
    const Pose2 guess = truth * RandomOffset(rng, 0.08, 0.05);
    const std::optional<MatchResult> m = matcher.Match(scan, guess);
    ASSERT_TRUE(m.has_value());
    EXPECT_LT((m->pose.translation() - truth.translation()).norm(), 0.01) << trial;
    EXPECT_LT(YawError(m->pose, truth), 0.003) << trial;
  }
}

// 20 % of the source's beams return short at a random range (the beam model's random and short
// readings: clutter, people): trimmed ICP with a robust kernel still converges to the truth, and
// no worse than without them.
TEST(IcpMatcherTest, TrimmedIcpIgnoresTwentyPercentOutliers) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(5);
  const RangeFinderSpec spec;
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  for (const auto& [metric, kernel] : {std::pair{IcpMetric::kPointToPoint, RobustKernel::kCauchy},
                                       {IcpMetric::kPointToLine, RobustKernel::kCauchy},
                                       {IcpMetric::kPointToLine, RobustKernel::kHuber}}) {
    IcpOptions trimmed;
    trimmed.metric = metric;
    trimmed.trim_fraction = 0.9;
    trimmed.kernel = kernel;
    IcpOptions plain;
    plain.metric = metric;
    const bool to_line = metric == IcpMetric::kPointToLine;
    const double xy_tolerance = to_line ? 0.012 : 0.025, yaw_tolerance = to_line ? 0.004 : 0.01;
    double plain_error_sum = 0.0, trimmed_error_sum = 0.0;
    for (int trial = 0; trial < 25; ++trial) {
      const Pose2 a = RandomCorridorPose(rng);
      const Pose2 offset = RandomOffset(rng, 0.05, 0.05);
      const std::vector<Eigen::Vector2d> ref =
          ScanToBasePoints(world.Scan(a, Time(), spec, &rng), points);
      std::vector<Eigen::Vector2d> src =
          ScanToBasePoints(world.Scan(a * offset, Time(), spec, &rng), points);
      for (std::size_t i = 0; i < src.size(); i += 5) src[i] *= 0.05 + 0.95 * Uniform01(rng);
      const std::optional<MatchResult> t = IcpMatcher(trimmed, ref).Match(src, Pose2());
      const std::optional<MatchResult> p = IcpMatcher(plain, ref).Match(src, Pose2());
      ASSERT_TRUE(t.has_value() && p.has_value());
      const double t_err = (t->pose.translation() - offset.translation()).norm();
      EXPECT_LT(t_err, xy_tolerance) << trial;
      EXPECT_LT(YawError(t->pose, offset), yaw_tolerance) << trial;
      trimmed_error_sum += t_err;
      plain_error_sum += (p->pose.translation() - offset.translation()).norm();
    }
    EXPECT_LT(trimmed_error_sum, plain_error_sum)
        << static_cast<int>(metric) << " " << static_cast<int>(kernel);
  }
}

// Two parallel walls along a direction at 30 degrees: the point-to-line covariance's major axis
// lies along the corridor and is far larger than across it.
TEST(IcpMatcherTest, CovarianceIsLargestAlongACorridorsAxis) {
  const double axis = 0.5236;
  const Eigen::Vector2d u(std::cos(axis), std::sin(axis)), n(-std::sin(axis), std::cos(axis));
  const SegmentWorld world({{-100.0 * u + n, 100.0 * u + n}, {-100.0 * u - n, 100.0 * u - n}});
  RandomEngine rng(9);
  const RangeFinderSpec spec;
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  for (int trial = 0; trial < 10; ++trial) {
    const Pose2 a(0.0, 0.0, 6.28 * Uniform01(rng));
    const Pose2 offset = RandomOffset(rng, 0.03, 0.03);
    const LaserScan src = world.Scan(a * offset, Time(), spec, &rng);  // noise drawn first
    const LaserScan ref = world.Scan(a, Time(), spec, &rng);
    const std::optional<MatchResult> m =
        IcpMatcher::MatchScans(IcpOptions{}, points, ref, src, Pose2());
    ASSERT_TRUE(m.has_value());
    // The covariance in the world frame: rotate the (x, y) block of the base-frame estimate.
    const Eigen::Matrix2d r = Eigen::Rotation2Dd(a.theta()).toRotationMatrix();
    const Eigen::Matrix2d cov = r * m->covariance.topLeftCorner<2, 2>() * r.transpose();
    const double along = u.dot(cov * u), across = n.dot(cov * n);
    EXPECT_GT(along, 100.0 * across) << trial;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    EXPECT_GT(std::abs(eig.eigenvectors().col(1).dot(u)), 0.999) << trial;
    // Across the corridor and in yaw the match is still exact.
    const Eigen::Vector2d error = r * (m->pose.translation() - offset.translation());
    EXPECT_LT(std::abs(n.dot(error)), 0.005) << trial;
    EXPECT_LT(YawError(m->pose, offset), 0.003) << trial;
  }
}

// In the office, with walls in every direction, the same covariance is nearly isotropic: the
// contrast that makes the corridor's ratio a degeneracy test.
TEST(IcpMatcherTest, CovarianceIsNearlyIsotropicWhereWallsFaceEveryWay) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(19);
  ScanPointsOptions points;
  points.voxel_size_m = 0.05;
  for (int trial = 0; trial < 10; ++trial) {
    const Pose2 a = RandomCorridorPose(rng);
    const LaserScan src =  // noise drawn first
        world.Scan(a * Pose2(0.02, 0.01, 0.01), Time(), RangeFinderSpec{}, &rng);
    const LaserScan ref = world.Scan(a, Time(), RangeFinderSpec{}, &rng);
    const std::optional<MatchResult> m =
        IcpMatcher::MatchScans(IcpOptions{}, points, ref, src, Pose2());
    ASSERT_TRUE(m.has_value());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(m->covariance.topLeftCorner<2, 2>());
    EXPECT_LT(eig.eigenvalues()[1], 30.0 * eig.eigenvalues()[0]) << trial;
  }
}

// The predicted covariance matches the spread of estimates over noise draws (within a factor 3).
TEST(IcpMatcherTest, CovarianceMatchesTheSpreadOverNoiseDraws) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(13);
  RangeFinderSpec spec;
  spec.range_sigma_m = 0.02;
  ScanPointsOptions points;
  points.beam_stride = 3;
  const Pose2 a(8.0, 2.0, 0.3);
  // A noise-free reference, so the spread comes from the source's noise alone.
  const IcpMatcher matcher(IcpOptions{},
                           ScanToBasePoints(world.Scan(a, Time(), spec, nullptr), points));
  const int n = 60;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero(), predicted = Eigen::Matrix3d::Zero();
  for (int trial = 0; trial < n; ++trial) {
    const std::vector<Eigen::Vector2d> src =
        ScanToBasePoints(world.Scan(a, Time(), spec, &rng), points);
    const std::optional<MatchResult> m = matcher.Match(src, Pose2(0.02, -0.01, 0.01));
    ASSERT_TRUE(m.has_value());
    const Eigen::Vector3d e(m->pose.x(), m->pose.y(), m->pose.theta());
    sum += e;
    sum_sq += e * e.transpose();
    predicted += m->covariance / n;
  }
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d empirical = sum_sq / n - mean * mean.transpose();
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(empirical(i, i), predicted(i, i) / 3.0) << i;
    EXPECT_LT(empirical(i, i), predicted(i, i) * 3.0) << i;
  }
}

TEST(IcpMatcherTest, FailsWhenTheSourceIsFarFromTheReference) {
  const SegmentWorld world = SegmentWorld::Office();
  const ScanPointsOptions points;
  const std::vector<Eigen::Vector2d> ref = ScanToBasePoints(
      world.Scan(Pose2(8.0, 2.0, 0.0), Time(), RangeFinderSpec{}, nullptr), points);
  const IcpMatcher matcher(IcpOptions{}, ref);
  EXPECT_FALSE(matcher.Match(ref, Pose2(50.0, 50.0, 0.0)).has_value());
  const IcpMatcher empty(IcpOptions{}, {});
  EXPECT_FALSE(empty.Match(ref, Pose2()).has_value());
}

// A reference point's normal is the minor principal axis of its nearest neighbours within the
// radius (brute force here), computed once whichever thread asks first.
TEST(IcpMatcherTest, NormalsAreTheMinorAxisOfTheNearestNeighbours) {
  RandomEngine rng(51);
  std::vector<Eigen::Vector2d> points;
  for (int p = 0; p < 300; ++p) {
    // Points along a few random walls, with noise: most normals are well defined.
    const double t = Uniform01(rng);
    const int wall = p % 3;
    const Eigen::Vector2d dir(std::cos(wall * 1.1), std::sin(wall * 1.1));
    const double noise = 0.01 * (Uniform01(rng) - 0.5);
    const Eigen::Vector2d across(-dir.y(), dir.x());
    points.push_back(Eigen::Vector2d(wall * 2.0, wall) + 4.0 * t * dir + noise * across);
  }
  points.emplace_back(50.0, 50.0);  // alone: no normal
  IcpOptions options;
  options.metric = IcpMetric::kPointToLine;
  const IcpMatcher matcher(options, points);
  const IcpMatcher twin(options, points);
  // The twin's normals are asked for from two threads at once, in opposite orders.
  std::vector<Eigen::Vector2d> forward(points.size()), backward(points.size());
  std::thread other([&] {
    for (std::size_t i = points.size(); i-- > 0;)
      backward[i] = twin.Normal(static_cast<std::uint32_t>(i));
  });
  for (std::size_t i = 0; i < points.size(); ++i)
    forward[i] = twin.Normal(static_cast<std::uint32_t>(i));
  other.join();
  int with_normal = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<std::pair<double, std::size_t>> by_distance;
    for (std::size_t j = 0; j < points.size(); ++j) {
      by_distance.emplace_back((points[j] - points[i]).squaredNorm(), j);
    }
    std::sort(by_distance.begin(), by_distance.end());
    std::vector<Eigen::Vector2d> near;
    for (std::size_t k = 0; k < static_cast<std::size_t>(options.normal_neighbors); ++k) {
      if (by_distance[k].first > options.normal_radius_m * options.normal_radius_m) break;
      near.push_back(points[by_distance[k].second]);
    }
    const Eigen::Vector2d normal = matcher.Normal(static_cast<std::uint32_t>(i));
    EXPECT_EQ(forward[i], normal) << i;
    EXPECT_EQ(backward[i], normal) << i;
    if (near.size() < 3) {
      EXPECT_EQ(normal, Eigen::Vector2d::Zero()) << i;
      continue;
    }
    ++with_normal;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& q : near) mean += q;
    mean /= static_cast<double>(near.size());
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& q : near) scatter += (q - mean) * (q - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    EXPECT_NEAR(normal.norm(), 1.0, 1e-12) << i;
    EXPECT_NEAR(std::abs(normal.dot(eig.eigenvectors().col(0))), 1.0, 1e-9) << i;
  }
  EXPECT_GT(with_normal, 250);
  EXPECT_EQ(matcher.Normal(static_cast<std::uint32_t>(points.size() - 1)), Eigen::Vector2d::Zero());
  // Point-to-point: no normals.
  IcpOptions to_points;
  to_points.metric = IcpMetric::kPointToPoint;
  const IcpMatcher plain(to_points, points);
  EXPECT_FALSE(plain.has_normals());
  EXPECT_EQ(plain.Normal(0), Eigen::Vector2d::Zero());
}

TEST(IcpOptionsTest, ValidateNamesEveryBrokenField) {
  IcpOptions options;
  EXPECT_TRUE(options.Validate().empty());
  options.trim_fraction = 0.0;
  options.max_correspondence_distance_m = -1.0;
  options.normal_neighbors = 2;
  const std::vector<std::string> errors = options.Validate();
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0], "max_correspondence_distance_m = -1; must be > 0");
  EXPECT_EQ(errors[1], "trim_fraction = 0; must be in (0, 1]");
  EXPECT_EQ(errors[2], "normal_neighbors = 2; must be >= 3");
}

}  // namespace
}  // namespace slamrig::slam
