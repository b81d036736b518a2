#include "slam/matching/scan_refiner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "slam/matching/likelihood_field.h"
#include "slam/matching/scan_points.h"
#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

// On the likelihood field of a mapped office, a pose off by less than two cells and 0.02 rad is
// pulled back to well under a cell: the refinement works below the grid resolution.
TEST(ScanRefinerTest, RecoversSubCellOffsets) {
  const testing::SegmentWorld world = testing::SegmentWorld::Office();
  const testing::RangeFinderSpec spec;
  OccupancyGrid grid(OccupancyGridOptions{});
  const Pose2 truth(6.02, 1.53, 0.11);
  for (int i = 0; i < 3; ++i) grid.InsertScan(world.Scan(truth, Time{}, spec, nullptr), truth);
  LikelihoodFieldOptions field_options;
  field_options.sigma_m = 0.08;
  LikelihoodField field(field_options);
  field.Update(grid, Eigen::AlignedBox2d(Eigen::Vector2d(-5, -5), Eigen::Vector2d(25, 17)));
  ScanPointsOptions point_options;
  point_options.voxel_size_m = 0.05;
  RandomEngine rng(5);
  const std::vector<Eigen::Vector2d> points =
      ScanToBasePoints(world.Scan(truth, Time{}, spec, &rng), point_options);
  ScanRefinerOptions options;
  options.max_iterations = 20;
  const ScanRefiner refiner(options);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d d = 2.0 * Uniform3(rng) - Eigen::Vector3d::Ones();
    const Pose2 start(truth.x() + 0.08 * d.x(), truth.y() + 0.08 * d.y(),
                      truth.theta() + 0.02 * d.z());
    const RefineResult r =
        refiner.Refine(field.view(), static_cast<float>(field.Score(0.0)), points, start);
    EXPECT_NEAR(r.pose.x(), truth.x(), 0.015) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.015) << trial;
    EXPECT_NEAR(r.pose.theta(), truth.theta(), 0.003) << trial;
    EXPECT_GE(r.score, ScanRefiner::Score(field.view(), points, start));
  }
}

// Two long parallel walls: nothing pins x. With the prior the refiner keeps the predicted x
// within a prior sigma (Gauss-Newton on the flat direction alone follows the map's noise) and
// keeps y and yaw on the walls.
TEST(ScanRefinerTest, PriorHoldsTheFlatDirectionOfACorridor) {
  const testing::SegmentWorld world({{{-30.0, 1.2}, {90.0, 1.2}}, {{-30.0, -1.2}, {90.0, -1.2}}});
  testing::RangeFinderSpec spec;
  spec.range_max_m = 8.0;  // the scans never see where the mapped walls end
  OccupancyGrid grid(OccupancyGridOptions{});
  RandomEngine rng(9);
  for (double x = 9.0; x <= 11.0; x += 0.25) {
    grid.InsertScan(world.Scan(Pose2(x, 0.0, 0.0), Time{}, spec, &rng), Pose2(x, 0.0, 0.0));
  }
  LikelihoodField field(LikelihoodFieldOptions{0.08, 0.9, 0.1, 0.0f, 3.0});
  field.Update(grid, Eigen::AlignedBox2d(Eigen::Vector2d(-25, -5), Eigen::Vector2d(45, 5)));
  ScanPointsOptions point_options;
  point_options.voxel_size_m = 0.05;
  ScanRefinerOptions options;
  options.max_iterations = 20;
  options.prior_sigma_xy_m = 0.01;
  options.prior_sigma_yaw_rad = 0.02;
  const ScanRefiner refiner(options);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose2 truth(9.5 + 0.1 * trial, 0.0, 0.0);
    const std::vector<Eigen::Vector2d> points =
        ScanToBasePoints(world.Scan(truth, Time{}, spec, &rng), point_options);
    const Pose2 predicted(truth.x() + 0.03, 0.0, 0.0);
    const RefineResult r =
        refiner.Refine(field.view(), static_cast<float>(field.Score(0.0)), points, predicted);
    EXPECT_NEAR(r.pose.x(), predicted.x(), 0.01) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.01) << trial;
    EXPECT_NEAR(r.pose.theta(), truth.theta(), 0.002) << trial;
  }
}

// With maximise_score the refinement climbs the score itself: from starts spread over two cells
// and 0.04 rad it ends within a few millimetres and 0.003 rad of the maximum that a dense search of
// the score finds (1 mm, 0.0002 rad steps around the truth; the score is that flat along a ridge
// that couples x and heading), and on average much closer to its value than Hector's residual
// objective, which stops between its own optimum and the score's.
TEST(ScanRefinerTest, MaximisingTheScoreEndsNearItsMaximumWhereverItStarts) {
  const testing::SegmentWorld world = testing::SegmentWorld::Office();
  const testing::RangeFinderSpec spec;
  OccupancyGrid grid(OccupancyGridOptions{});
  const Pose2 truth(6.02, 1.53, 0.11);
  RandomEngine rng(7);
  for (int i = 0; i < 3; ++i) grid.InsertScan(world.Scan(truth, Time{}, spec, &rng), truth);
  LikelihoodField field(LikelihoodFieldOptions{0.08, 0.9, 0.1, 0.0f, 3.0});
  field.Update(grid, Eigen::AlignedBox2d(Eigen::Vector2d(-5, -5), Eigen::Vector2d(25, 17)));
  const float field_max = static_cast<float>(field.Score(0.0));
  ScanPointsOptions point_options;
  point_options.voxel_size_m = 0.05;
  const std::vector<Eigen::Vector2d> points =
      ScanToBasePoints(world.Scan(truth, Time{}, spec, &rng), point_options);
  // The independent maximum: a dense search around the truth.
  double best_score = -1.0;
  Pose2 best;
  for (int i = -20; i <= 20; ++i) {
    for (int j = -20; j <= 20; ++j) {
      for (int k = -15; k <= 15; ++k) {
        const Pose2 pose(truth.x() + 0.001 * i, truth.y() + 0.001 * j, truth.theta() + 0.0002 * k);
        const double score = ScanRefiner::Score(field.view(), points, pose);
        if (score > best_score) best_score = score, best = pose;
      }
    }
  }
  ScanRefinerOptions options;
  options.max_iterations = 20;
  options.maximise_score = true;
  const ScanRefiner climber(options);
  options.maximise_score = false;
  const ScanRefiner hector(options);
  constexpr int kTrials = 20;
  double climber_deficit = 0.0, hector_deficit = 0.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Eigen::Vector3d d = 2.0 * Uniform3(rng) - Eigen::Vector3d::Ones();
    const Pose2 start(truth.x() + 0.05 * d.x(), truth.y() + 0.05 * d.y(),
                      truth.theta() + 0.02 * d.z());
    const RefineResult r = climber.Refine(field.view(), field_max, points, start);
    EXPECT_NEAR(r.pose.x(), best.x(), 0.008) << trial;
    EXPECT_NEAR(r.pose.y(), best.y(), 0.004) << trial;
    EXPECT_NEAR(r.pose.theta(), best.theta(), 0.003) << trial;
    EXPECT_GE(r.score, best_score - 5e-4 * best_score) << trial;
    EXPECT_GE(r.score, ScanRefiner::Score(field.view(), points, start)) << trial;
    climber_deficit += std::max(0.0, best_score - r.score) / kTrials;
    const RefineResult h = hector.Refine(field.view(), field_max, points, start);
    hector_deficit += std::max(0.0, best_score - h.score) / kTrials;
  }
  EXPECT_LT(climber_deficit, 0.5 * hector_deficit);
}

TEST(ScanRefinerTest, ValidateNamesFieldValueAndRule) {
  ScanRefinerOptions options;
  options.max_step_m = 0.0;
  EXPECT_THAT(options.Validate(), ::testing::ElementsAre("max_step_m = 0; must be > 0"));
  options = ScanRefinerOptions{};
  options.prior_sigma_yaw_rad = -1.0;
  EXPECT_THAT(options.Validate(), ::testing::ElementsAre("prior_sigma_yaw_rad = -1; must be >= 0"));
  options = ScanRefinerOptions{};
  options.max_halvings = -1;
  EXPECT_THAT(options.Validate(), ::testing::ElementsAre("max_halvings = -1; must be >= 0"));
}

}  // namespace
}  // namespace slamrig::slam
