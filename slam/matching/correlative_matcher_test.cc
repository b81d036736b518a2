#include "slam/matching/correlative_matcher.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "slam/matching/scan_points.h"
#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

using testing::RangeFinderSpec;
using testing::SegmentWorld;

// 25 points uniform in [-0.8, 0.8)^2 (y drawn first, as in Uniform3).
std::vector<Eigen::Vector2d> RandomPoints(RandomEngine& rng) {
  std::vector<Eigen::Vector2d> points;
  for (int p = 0; p < 25; ++p) {
    const double y = 1.6 * Uniform01(rng) - 0.8;
    points.emplace_back(1.6 * Uniform01(rng) - 0.8, y);
  }
  return points;
}

// Independent exhaustive search over the window, as CorrelativeMatcher's header defines it: every
// yaw k, every (j, i) in order, the float sum of the raster at the discretised points; the first
// strictly better pose wins, so ties go to the smallest (k, j, i). Poses within `distance_m` and
// `angle_rad` of one of `excluded` are skipped.
std::optional<MatchResult> ExhaustiveSearch(const GridView& raster,
                                            const std::vector<Eigen::Vector2d>& points,
                                            const Pose2& initial, int wxy, int wk, double step,
                                            double min_score,
                                            const std::vector<Pose2>& excluded = {},
                                            double distance_m = 0.0, double angle_rad = 0.0) {
  const int n = static_cast<int>(points.size());
  std::optional<MatchResult> best;
  float best_sum = 0.0f;
  for (int k = -wk; k <= wk; ++k) {
    const Pose2 rotated(initial.x(), initial.y(), initial.theta() + k * step);
    std::vector<Eigen::Array2i> cells;
    for (const Eigen::Vector2d& p : points) {
      const Eigen::Vector2d w = rotated * p;
      cells.emplace_back(
          static_cast<int>(std::floor((w.x() - raster.origin.x()) / raster.resolution)),
          static_cast<int>(std::floor((w.y() - raster.origin.y()) / raster.resolution)));
    }
    for (int j = -wxy; j <= wxy; ++j) {
      for (int i = -wxy; i <= wxy; ++i) {
        float sum = 0.0f;
        for (const Eigen::Array2i& c : cells) sum += raster.At(c.x() + i, c.y() + j);
        if (static_cast<double>(sum) < min_score * n) continue;
        if (best && !(sum > best_sum)) continue;
        const Pose2 pose(initial.x() + i * raster.resolution, initial.y() + j * raster.resolution,
                         initial.theta() + k * step);
        bool near = false;
        for (const Pose2& e : excluded) {
          near = near || ((pose.translation() - e.translation()).norm() <= distance_m &&
                          std::abs(NormalizeAngle(pose.theta() - e.theta())) <= angle_rad);
        }
        if (near) continue;
        best_sum = sum;
        best = MatchResult{};
        best->pose = pose;
        best->score = static_cast<double>(sum) / n;
      }
    }
  }
  return best;
}

OccupancyGrid MapFromScans(const SegmentWorld& world, const std::vector<Pose2>& poses,
                           RandomEngine& rng) {
  OccupancyGrid grid{OccupancyGridOptions{}};
  for (const Pose2& pose : poses)
    grid.InsertScan(world.Scan(pose, Time(), RangeFinderSpec{}, &rng), pose);
  return grid;
}

// Poses round the office's corridor loop every 0.5 m, facing along it.
std::vector<Pose2> OfficeLoopPoses() {
  std::vector<Pose2> poses;
  for (double x = 1.5; x <= 18.5; x += 0.5) poses.emplace_back(x, 1.5, 0.0);
  for (double y = 1.5; y <= 10.5; y += 0.5) poses.emplace_back(18.5, y, 1.57);
  for (double x = 18.5; x >= 1.5; x -= 0.5) poses.emplace_back(x, 10.5, 3.14);
  for (double y = 10.5; y >= 1.5; y -= 0.5) poses.emplace_back(1.5, y, -1.57);
  return poses;
}

// Branch and bound returns exactly the exhaustive search's best pose and score, on random rasters
// with continuous values and with three levels only (many ties), at every depth.
TEST(CorrelativeMatcherTest, BranchAndBoundEqualsExhaustiveSearch) {
  RandomEngine rng(21);
  int found = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int width = 30 + static_cast<int>(20 * Uniform01(rng));
    const int height = 30 + static_cast<int>(20 * Uniform01(rng));
    std::vector<float> values(static_cast<std::size_t>(width) * height);
    const bool ties = trial % 2 == 1;
    for (float& v : values) {
      const double u = Uniform01(rng);
      v = ties ? static_cast<float>(std::floor(3.0 * u) / 2.0) : static_cast<float>(u * u);
    }
    const GridView raster{values.data(), width, height, Eigen::Vector2d(-1.0, -0.9), 0.05};
    const std::vector<Eigen::Vector2d> points = RandomPoints(rng);
    CorrelativeMatcherOptions options;
    options.linear_window_m = 0.3 + 0.2 * Uniform01(rng);
    options.angular_window_rad = 0.2;
    options.angular_step_rad = 0.04;
    options.branch_and_bound_depth = 1 + trial % 6;
    options.min_score = trial % 3 == 0 ? 0.75 : 0.0;
    const CorrelativeMatcher matcher(options, raster);
    const Eigen::Vector3d d = Uniform3(rng);
    const Pose2 initial(0.3 * d.x(), 0.3 * d.y(), 6.0 * d.z());
    const std::optional<MatchResult> fast = matcher.Match(points, initial);
    const int wxy = static_cast<int>(std::ceil(options.linear_window_m / 0.05 - 1e-9));
    const std::optional<MatchResult> slow =
        ExhaustiveSearch(raster, points, initial, wxy, 5, 0.04, options.min_score);
    ASSERT_EQ(fast.has_value(), slow.has_value()) << trial;
    if (!slow) continue;
    ++found;
    EXPECT_EQ(fast->pose, slow->pose) << trial;
    EXPECT_EQ(fast->score, slow->score) << trial;
  }
  EXPECT_GT(found, 30);
}

// Each level's bound is the brute-force maximum of its block (Hess 2016, Sec. V-C), on random
// rasters of every shape down to a single row or column, at every depth.
TEST(CorrelativeMatcherTest, EachLevelHoldsTheMaximumOfItsBlock) {
  RandomEngine rng(23);
  for (int trial = 0; trial < 40; ++trial) {
    const int width = 1 + static_cast<int>(40 * Uniform01(rng));
    const int height = 1 + static_cast<int>(40 * Uniform01(rng));
    std::vector<float> values(static_cast<std::size_t>(width) * height);
    for (float& v : values) {
      const double u = Uniform01(rng);
      v = static_cast<float>(u * Uniform01(rng));
    }
    const GridView raster{values.data(), width, height, Eigen::Vector2d::Zero(), 0.1};
    CorrelativeMatcherOptions options;
    options.branch_and_bound_depth = 1 + trial % 8;
    const CorrelativeMatcher matcher(options, raster);
    for (int level = 0; level < options.branch_and_bound_depth; ++level) {
      const int side = 1 << level;
      for (int y = -side - 1; y <= height + 1; ++y) {
        for (int x = -side - 1; x <= width + 1; ++x) {
          float expected = 0.0f;
          if (x > -side && y > -side && x < width && y < height) {
            for (int by = std::max(y, 0); by < std::min(y + side, height); ++by) {
              for (int bx = std::max(x, 0); bx < std::min(x + side, width); ++bx) {
                expected = std::max(expected, values[static_cast<std::size_t>(by) * width + bx]);
              }
            }
          }
          ASSERT_EQ(matcher.LevelBound(level, x, y), expected)
              << "trial " << trial << " level " << level << " at (" << x << ", " << y << ")";
        }
      }
    }
  }
}

// The distinct places are the greedy non-maximum suppression of the exhaustive search: each is
// the best pose outside the neighbourhoods of those before it, on random rasters, at every depth.
TEST(CorrelativeMatcherTest, DistinctPlacesAreTheExhaustiveSearchsSuppressedMaxima) {
  RandomEngine rng(22);
  int second = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int width = 30 + static_cast<int>(20 * Uniform01(rng));
    const int height = 30 + static_cast<int>(20 * Uniform01(rng));
    std::vector<float> values(static_cast<std::size_t>(width) * height);
    const bool ties = trial % 2 == 1;
    for (float& v : values) {
      const double u = Uniform01(rng);
      v = ties ? static_cast<float>(std::floor(3.0 * u) / 2.0) : static_cast<float>(u * u);
    }
    const GridView raster{values.data(), width, height, Eigen::Vector2d(-1.0, -0.9), 0.05};
    const std::vector<Eigen::Vector2d> points = RandomPoints(rng);
    CorrelativeMatcherOptions options;
    options.linear_window_m = 0.3 + 0.2 * Uniform01(rng);
    options.angular_window_rad = 0.2;
    options.angular_step_rad = 0.04;
    options.branch_and_bound_depth = 1 + trial % 6;
    options.min_score = trial % 4 == 0 ? 0.7 : 0.0;
    const CorrelativeMatcher matcher(options, raster);
    const Eigen::Vector3d d = Uniform3(rng);
    const Pose2 initial(0.3 * d.x(), 0.3 * d.y(), 6.0 * d.z());
    const double distance_m = 0.12 + 0.1 * Uniform01(rng), angle_rad = trial % 3 == 0 ? 0.1 : 1.0;
    const std::vector<MatchResult> fast =
        matcher.MatchDistinct(points, initial, 4, distance_m, angle_rad);
    const int wxy = static_cast<int>(std::ceil(options.linear_window_m / 0.05 - 1e-9));
    std::vector<Pose2> earlier;
    for (int r = 0; r < 4; ++r) {
      const std::optional<MatchResult> slow = ExhaustiveSearch(
          raster, points, initial, wxy, 5, 0.04, options.min_score, earlier, distance_m, angle_rad);
      ASSERT_EQ(static_cast<int>(fast.size()) > r, slow.has_value()) << trial << " " << r;
      if (!slow) break;
      EXPECT_EQ(fast[static_cast<std::size_t>(r)].pose, slow->pose) << trial << " " << r;
      EXPECT_EQ(fast[static_cast<std::size_t>(r)].score, slow->score) << trial << " " << r;
      earlier.push_back(slow->pose);
      second += r == 1;
    }
    const std::optional<MatchResult> single = matcher.Match(points, initial);
    ASSERT_EQ(single.has_value(), !fast.empty());
    if (single) {
      EXPECT_EQ(single->pose, fast.front().pose);
    }
  }
  EXPECT_GT(second, 20);
}

// A scan of the office from a random pose near its loop (any heading), and a guess up to 2 m and
// 3 rad away from that pose.
struct FarScan {
  Pose2 truth;
  Pose2 initial;
  std::vector<Eigen::Vector2d> points;
};
FarScan ScanFromFarAway(const SegmentWorld& world, const ScanPointsOptions& points,
                        RandomEngine& rng) {
  const std::vector<Pose2> loop = OfficeLoopPoses();
  const Pose2 base =
      loop[static_cast<std::size_t>(Uniform01(rng) * static_cast<double>(loop.size()))];
  FarScan far;
  const Eigen::Vector3d t = Uniform3(rng);
  far.truth = Pose2(base.x() + 0.4 * t.x() - 0.2, base.y() + 0.4 * t.y() - 0.2, 6.28 * t.z());
  far.points = ScanToBasePoints(world.Scan(far.truth, Time(), RangeFinderSpec{}, &rng), points);
  const Eigen::Vector3d i = Uniform3(rng);
  far.initial = Pose2(far.truth.x() + 4.0 * i.x() - 2.0, far.truth.y() + 4.0 * i.y() - 2.0,
                      far.truth.theta() + (2.0 * i.z() - 1.0) * 3.0);
  return far;
}

// On a map of the office, a decimated scan is found from an initial guess metres and up to pi off.
TEST(CorrelativeMatcherTest, RecoversLargeOffsetsOnAnOccupancyGrid) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(4);
  const OccupancyGrid grid = MapFromScans(world, OfficeLoopPoses(), rng);
  CorrelativeMatcherOptions options;
  options.linear_window_m = 2.5;
  options.branch_and_bound_depth = 6;
  options.min_score = 0.3;
  const CorrelativeMatcher matcher(options, grid);
  ScanPointsOptions points;
  points.voxel_size_m = 0.15;
  for (int trial = 0; trial < 8; ++trial) {
    const auto [truth, initial, scan] = ScanFromFarAway(world, points, rng);
    const std::optional<MatchResult> m = matcher.Match(scan, initial);
    ASSERT_TRUE(m.has_value()) << trial;
    EXPECT_LT((m->pose.translation() - truth.translation()).norm(), 0.08) << trial;
    EXPECT_LT(std::abs(NormalizeAngle(m->pose.theta() - truth.theta())), 0.02) << trial;
    EXPECT_GT(m->score, 0.5) << trial;
    // Walls in every direction: no direction is much less certain than another (the contrast
    // the corridor test below relies on).
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(m->covariance.topLeftCorner<2, 2>());
    EXPECT_LT(eig.eigenvalues()[1], 5.0 * eig.eigenvalues()[0]) << trial;
  }
}

// A grid searched d times coarser is searched as its max-pooled raster: the same poses and scores
// as the plain matcher on a raster pooled here cell by cell, distinct places included. And the
// coarse search still finds the office's scans from metres and up to pi away, to within a coarse
// cell in x and y and two yaw steps (pooling flattens the score across a coarse cell, so the
// discrete optimum may sit a step further; the relocaliser refines from there).
TEST(CorrelativeMatcherTest, ADecimatedGridIsSearchedAsItsMaxPooledRaster) {
  const SegmentWorld world = SegmentWorld::Office();
  RandomEngine rng(5);
  const OccupancyGrid grid = MapFromScans(world, OfficeLoopPoses(), rng);
  ScanPointsOptions points;
  points.voxel_size_m = 0.15;
  const std::vector<float> dense = grid.DenseLogOdds();
  for (const int d : {2, 3, 4}) {
    const int width = (grid.width() + d - 1) / d, height = (grid.height() + d - 1) / d;
    std::vector<float> pooled(static_cast<std::size_t>(width) * height, 0.0f);
    for (int cy = 0; cy < height; ++cy) {
      for (int cx = 0; cx < width; ++cx) {
        float& v = pooled[static_cast<std::size_t>(cy) * width + cx];
        for (int y = cy * d; y < std::min((cy + 1) * d, grid.height()); ++y) {
          for (int x = cx * d; x < std::min((cx + 1) * d, grid.width()); ++x) {
            const float l = dense[static_cast<std::size_t>(y) * grid.width() + x];
            if (l > 0.0f) v = std::max(v, static_cast<float>(1.0 - 1.0 / (1.0 + std::exp(l))));
          }
        }
      }
    }
    const GridView raster{pooled.data(), width, height, grid.origin(), d * grid.resolution()};
    CorrelativeMatcherOptions options;
    options.linear_window_m = 2.5;
    options.branch_and_bound_depth = 5;
    options.min_score = 0.3;
    const CorrelativeMatcher decimated(options, grid, d);
    const CorrelativeMatcher reference(options, raster);
    for (int trial = 0; trial < 6; ++trial) {
      const auto [truth, initial, scan] = ScanFromFarAway(world, points, rng);
      const std::vector<MatchResult> fast = decimated.MatchDistinct(scan, initial, 3, 1.0, 0.5);
      const std::vector<MatchResult> slow = reference.MatchDistinct(scan, initial, 3, 1.0, 0.5);
      ASSERT_EQ(fast.size(), slow.size()) << d << " " << trial;
      ASSERT_FALSE(fast.empty()) << d << " " << trial;
      for (std::size_t r = 0; r < fast.size(); ++r) {
        EXPECT_EQ(fast[r].pose, slow[r].pose) << d << " " << trial << " " << r;
        EXPECT_EQ(fast[r].score, slow[r].score) << d << " " << trial << " " << r;
      }
      const double cell = d * grid.resolution();
      EXPECT_DOUBLE_EQ(decimated.AngularStep(scan), reference.AngularStep(scan));
      EXPECT_LT((fast.front().pose.translation() - truth.translation()).norm(), cell)
          << d << " " << trial;
      EXPECT_LT(std::abs(NormalizeAngle(fast.front().pose.theta() - truth.theta())),
                2.0 * decimated.AngularStep(scan))
          << d << " " << trial;
    }
  }
}

// A scan from another building scores below min_score everywhere in the window: a failure, while
// a scan of the mapped place at the same spot is accepted.
TEST(CorrelativeMatcherTest, MinScoreRejectsAScanFromAnotherPlace) {
  const SegmentWorld office = SegmentWorld::Office();
  RandomEngine rng(8);
  const OccupancyGrid grid = MapFromScans(office, OfficeLoopPoses(), rng);
  CorrelativeMatcherOptions options;
  options.linear_window_m = 1.0;
  options.min_score = 0.5;
  const CorrelativeMatcher matcher(options, grid);
  SegmentWorld hall({});
  for (int s = 0; s < 7; ++s) {  // a heptagonal hall, 6 m across
    const double a0 = 2.0 * std::numbers::pi * s / 7.0, a1 = 2.0 * std::numbers::pi * (s + 1) / 7.0;
    hall = SegmentWorld([&] {
      std::vector<testing::Segment> walls = hall.walls();
      walls.push_back({Eigen::Vector2d(3.0 * std::cos(a0), 3.0 * std::sin(a0)),
                       Eigen::Vector2d(3.0 * std::cos(a1), 3.0 * std::sin(a1))});
      return walls;
    }());
  }
  ScanPointsOptions points;
  points.voxel_size_m = 0.1;
  const Pose2 here(9.0, 1.6, 0.2);
  const std::vector<Eigen::Vector2d> foreign =
      ScanToBasePoints(hall.Scan(Pose2(0.5, 0.0, 0.0), Time(), RangeFinderSpec{}, &rng), points);
  EXPECT_FALSE(matcher.Match(foreign, here).has_value());
  const std::vector<Eigen::Vector2d> local =
      ScanToBasePoints(office.Scan(here, Time(), RangeFinderSpec{}, &rng), points);
  const std::optional<MatchResult> m = matcher.Match(local, Pose2(9.3, 1.4, 0.0));
  ASSERT_TRUE(m.has_value());
  EXPECT_GE(m->score, 0.5);
  EXPECT_FALSE(matcher.Match(std::vector<Eigen::Vector2d>{}, here).has_value());
}

// Two parallel walls: the score is flat along the corridor, so the covariance is far larger along
// its axis than across it, and yaw stays well determined.
TEST(CorrelativeMatcherTest, CovarianceIsLargestAlongACorridorsAxis) {
  const SegmentWorld corridor({{{-60.0, 1.0}, {60.0, 1.0}}, {{-60.0, -1.0}, {60.0, -1.0}}});
  RandomEngine rng(2);
  std::vector<Pose2> poses;
  for (double x = -10.0; x <= 10.0; x += 1.0) poses.emplace_back(x, 0.0, 0.0);
  const OccupancyGrid grid = MapFromScans(corridor, poses, rng);
  CorrelativeMatcherOptions options;
  options.linear_window_m = 0.5;
  options.angular_window_rad = 0.1;
  options.min_score = 0.3;
  const CorrelativeMatcher matcher(options, grid);
  ScanPointsOptions points;
  points.voxel_size_m = 0.1;
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector3d d = Uniform3(rng);
    const Pose2 truth(2.0 * d.x() - 1.0, 0.4 * d.y() - 0.2, 0.2 * d.z() - 0.1);
    const std::vector<Eigen::Vector2d> scan =
        ScanToBasePoints(corridor.Scan(truth, Time(), RangeFinderSpec{}, &rng), points);
    const std::optional<MatchResult> m =
        matcher.Match(scan, Pose2(truth.x() + 0.2, truth.y() - 0.15, truth.theta() + 0.05));
    ASSERT_TRUE(m.has_value()) << trial;
    EXPECT_GT(m->covariance(0, 0), 20.0 * m->covariance(1, 1)) << trial;
    EXPECT_LT(std::abs(m->pose.y() - truth.y()), 0.06) << trial;
    EXPECT_LT(std::abs(NormalizeAngle(m->pose.theta() - truth.theta())), 0.01) << trial;
  }
}

TEST(CorrelativeMatcherOptionsTest, ValidateNamesEveryBrokenField) {
  CorrelativeMatcherOptions options;
  EXPECT_TRUE(options.Validate().empty());
  options.linear_window_m = -1.0;
  options.branch_and_bound_depth = 0;
  options.covariance_score_scale = 0.0;
  const std::vector<std::string> errors = options.Validate();
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0], "linear_window_m = -1; must be >= 0");
  EXPECT_EQ(errors[1], "branch_and_bound_depth = 0; must be in [1, 12]");
  EXPECT_EQ(errors[2], "covariance_score_scale = 0; must be > 0");
}

}  // namespace
}  // namespace slamrig::slam
