#include "slam/matching/map_correlator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "slam/matching/scan_points.h"
#include "slam/matching/testing/segment_world.h"

namespace slamrig::slam {
namespace {

// Independent reference: transform every point with the shifted pose, floor, drop consecutive
// duplicates, sum the cell contributions.
float NaiveScore(const GridView& grid, const std::vector<Eigen::Vector2d>& points,
                 const Pose2& shifted, const MapCorrelatorOptions& options) {
  float sum = 0.0f;
  int last_x = -1 << 30, last_y = 0;
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d w = shifted * p;
    const int ix = static_cast<int>(std::floor((w.x() - grid.origin.x()) / grid.resolution));
    const int iy = static_cast<int>(std::floor((w.y() - grid.origin.y()) / grid.resolution));
    if (ix == last_x && iy == last_y) continue;
    last_x = ix;
    last_y = iy;
    const float v = grid.At(ix, iy);
    sum += options.value == CorrelationValue::kRawValue
               ? v
               : (v > options.occupied_threshold ? 1.0f : 0.0f);
  }
  return sum;
}

struct RandomRaster {
  std::vector<float> values;
  GridView view;
};

RandomRaster MakeRaster(RandomEngine& rng, int width, int height) {
  RandomRaster r;
  r.values.resize(static_cast<std::size_t>(width) * height);
  for (float& v : r.values) v = static_cast<float>(3.0 * (Uniform01(rng) - 0.6));
  r.view = GridView{r.values.data(), width, height, Eigen::Vector2d(-1.3, -0.7), 0.05};
  return r;
}

TEST(MapCorrelatorTest, MatchesBruteForceOnRandomRastersIncludingEdges) {
  RandomEngine rng(11);
  RandomRaster raster = MakeRaster(rng, 60, 50);
  for (const CorrelationValue value :
       {CorrelationValue::kOccupiedIndicator, CorrelationValue::kRawValue}) {
    MapCorrelatorOptions options;
    options.value = value;
    options.yaw_half_steps = 1;
    options.yaw_step_rad = 0.02;
    const MapCorrelator correlator(options);
    for (int trial = 0; trial < 30; ++trial) {
      std::vector<Eigen::Vector2d> points;
      for (int i = 0; i < 200; ++i) {
        // Clustered points so consecutive duplicates occur; some fall off the raster.
        points.emplace_back(0.8 * std::cos(0.03 * i) + 0.001 * i,
                            0.8 * std::sin(0.03 * i) * (1 + trial % 3));
      }
      const Pose2 pose(0.2 + 0.4 * Uniform01(rng), 0.3 + 0.4 * Uniform01(rng),
                       6.0 * Uniform01(rng));
      std::vector<float> table;
      const CorrelationResult result = correlator.Correlate(raster.view, points, pose, &table);
      float best = -1e30f;
      for (int k = -1; k <= 1; ++k) {
        for (int dy = -4; dy <= 4; ++dy) {
          for (int dx = -4; dx <= 4; ++dx) {
            const Pose2 shifted(pose.x() + dx * 0.05, pose.y() + dy * 0.05,
                                pose.theta() + k * 0.02);
            const float naive = NaiveScore(raster.view, points, shifted, options);
            const float fast = table[static_cast<std::size_t>(((k + 1) * 9 + dy + 4) * 9 + dx + 4)];
            ASSERT_NEAR(fast, naive, 1e-3) << trial << " " << k << " " << dx << " " << dy;
            best = std::max(best, naive);
          }
        }
      }
      EXPECT_NEAR(result.score, best, 1e-3);
    }
  }
}

// Builds a map of the office from one pose, then finds that pose again from a perturbed start.
TEST(MapCorrelatorTest, RecoversARandomOffsetInsideItsWindow) {
  const testing::SegmentWorld world = testing::SegmentWorld::Office();
  const testing::RangeFinderSpec spec;
  OccupancyGridOptions grid_options;
  grid_options.update_once_per_scan = true;
  OccupancyGrid grid(grid_options);
  const Pose2 truth(2.0, 1.5, 0.3);
  RandomEngine rng(3);
  for (int i = 0; i < 3; ++i) grid.InsertScan(world.Scan(truth, Time{}, spec, &rng), truth);
  const std::vector<Eigen::Vector2d> points =
      ScanToBasePoints(world.Scan(truth, Time{}, spec, &rng), ScanPointsOptions{});

  MapCorrelatorOptions options;
  options.yaw_half_steps = 3;
  options.yaw_step_rad = 0.01;
  const MapCorrelator correlator(options);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose2 start(truth.x() + 0.17 * (2.0 * Uniform01(rng) - 1.0),
                      truth.y() + 0.17 * (2.0 * Uniform01(rng) - 1.0),
                      truth.theta() + 0.025 * (2.0 * Uniform01(rng) - 1.0));
    const CorrelationResult r = correlator.Correlate(GridView::Of(grid), points, start);
    EXPECT_NEAR(r.pose.x(), truth.x(), 0.051) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.051) << trial;
    // On a 5 cm grid the score is nearly flat over one or two 0.01 rad yaw steps.
    EXPECT_NEAR(r.pose.theta(), truth.theta(), 0.0201) << trial;
    EXPECT_GT(r.points_used, 300);
  }
}

TEST(MapCorrelatorTest, TiesPreferTheCentre) {
  std::vector<float> zeros(100 * 100, 0.0f);
  const GridView flat{zeros.data(), 100, 100, Eigen::Vector2d::Zero(), 0.1};
  const MapCorrelator correlator(MapCorrelatorOptions{});
  const std::vector<Eigen::Vector2d> points = {{1.0, 0.0}, {0.0, 1.0}};
  const CorrelationResult r = correlator.Correlate(flat, points, Pose2(5.0, 5.0, 0.0));
  EXPECT_EQ(r.dx_cells, 0);
  EXPECT_EQ(r.dy_cells, 0);
  EXPECT_EQ(r.pose, Pose2(5.0, 5.0, 0.0));
}

TEST(MapCorrelatorTest, ValidateNamesFieldValueAndRule) {
  MapCorrelatorOptions options;
  options.xy_half_width_cells = -1;
  options.yaw_half_steps = 2;
  options.yaw_step_rad = 0.0;
  EXPECT_THAT(
      options.Validate(),
      ::testing::ElementsAre("correlation.xy_half_width_cells = -1; must be in [0, 15]",
                             "correlation.yaw_step_rad = 0; must be > 0 when yaw_half_steps > 0"));
}

}  // namespace
}  // namespace slamrig::slam
