#include "slam/matching/scan_refiner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
    const Pose2 start(truth.x() + 0.08 * (2 * Uniform01(rng) - 1),
                      truth.y() + 0.08 * (2 * Uniform01(rng) - 1),
                      truth.theta() + 0.02 * (2 * Uniform01(rng) - 1));
    const RefineResult r =
        refiner.Refine(field.view(), static_cast<float>(field.Score(0.0)), points, start);
    EXPECT_NEAR(r.pose.x(), truth.x(), 0.015) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.015) << trial;
    EXPECT_NEAR(r.pose.theta(), truth.theta(), 0.003) << trial;
    EXPECT_GE(r.score, ScanRefiner::Score(field.view(), points, start));
  }
}

TEST(ScanRefinerTest, ValidateNamesFieldValueAndRule) {
  ScanRefinerOptions options;
  options.max_step_m = 0.0;
  EXPECT_THAT(options.Validate(), ::testing::ElementsAre("refine.max_step_m = 0; must be > 0"));
}

}  // namespace
}  // namespace slamrig::slam
