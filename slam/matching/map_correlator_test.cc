#include "slam/matching/map_correlator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "slam/matching/likelihood_field.h"
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

// The whole grid's log-odds as a raster of its own (the grid is tiles).
struct DenseGrid {
  explicit DenseGrid(const OccupancyGrid& grid)
      : values(grid.DenseLogOdds()),
        view{values.data(), grid.width(), grid.height(), grid.origin(), grid.resolution()} {}
  DenseGrid(const DenseGrid&) = delete;
  std::vector<float> values;
  GridView view;
};

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
      const Eigen::Vector3d d = Uniform3(rng);
      const Pose2 pose(0.2 + 0.4 * d.x(), 0.3 + 0.4 * d.y(), 6.0 * d.z());
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
    const Eigen::Vector3d d = 2.0 * Uniform3(rng) - Eigen::Vector3d::Ones();
    const Pose2 start(truth.x() + 0.17 * d.x(), truth.y() + 0.17 * d.y(),
                      truth.theta() + 0.025 * d.z());
    const CorrelationResult r = correlator.Correlate(DenseGrid(grid).view, points, start);
    EXPECT_NEAR(r.pose.x(), truth.x(), 0.051) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.051) << trial;
    // On a 5 cm grid the score is nearly flat over one or two 0.01 rad yaw steps.
    EXPECT_NEAR(r.pose.theta(), truth.theta(), 0.0201) << trial;
    EXPECT_GT(r.points_used, 300);
  }
}

// Two long parallel walls 2.4 m apart: seen from inside, a scan pins y and yaw but not x.
struct Corridor {
  testing::SegmentWorld world{{{{-30.0, 1.2}, {90.0, 1.2}}, {{-30.0, -1.2}, {90.0, -1.2}}}};
  testing::RangeFinderSpec spec;
  OccupancyGrid grid{OccupancyGridOptions{}};
  LikelihoodField field{LikelihoodFieldOptions{0.08, 0.9, 0.1, 0.0f, 3.0}};

  // Maps the corridor from a few poses along it, then computes the field around `around`.
  explicit Corridor(const Pose2& around) {
    RandomEngine rng(7);
    for (double x = around.x() - 1.0; x <= around.x() + 1.0; x += 0.25) {
      const Pose2 pose(x, 0.0, 0.0);
      grid.InsertScan(world.Scan(pose, Time{}, spec, &rng), pose);
    }
    field.Update(grid, Eigen::AlignedBox2d(around.translation() - Eigen::Vector2d(35, 5),
                                           around.translation() + Eigen::Vector2d(35, 5)));
  }
};

MapCorrelatorOptions CorridorSearch() {
  MapCorrelatorOptions options;
  options.yaw_half_steps = 4;
  options.yaw_step_rad = 0.0075;
  options.value = CorrelationValue::kRawValue;
  options.prior_sigma_xy_m = 0.01;
  options.prior_sigma_yaw_rad = 0.02;
  return options;
}

// Along the corridor the score is flat up to noise: with the motion prior the search keeps the
// predicted x (without it the best near-tie slides the pose by up to the window's half width),
// while it still corrects the constrained offsets across the corridor and in yaw.
TEST(MapCorrelatorTest, PriorKeepsTheAlongCorridorCoordinateAndFixesTheRest) {
  const Pose2 truth(10.0, 0.0, 0.0);
  const Corridor corridor(truth);
  const LikelihoodField& field = corridor.field;
  RandomEngine rng(21);
  const MapCorrelator correlator(CorridorSearch());
  for (int trial = 0; trial < 20; ++trial) {
    const Pose2 scan_pose(truth.x() + 0.5 * (2.0 * Uniform01(rng) - 1.0), 0.0, 0.0);
    const std::vector<Eigen::Vector2d> points = ScanToBasePoints(
        corridor.world.Scan(scan_pose, Time{}, corridor.spec, &rng), ScanPointsOptions{});
    // The prediction is off by 0.1 m across the corridor and 0.02 rad in yaw.
    const Pose2 predicted(scan_pose.x() + 0.1, scan_pose.y() + 0.1, 0.02);
    const CorrelationResult r = correlator.Correlate(field.view(), points, predicted);
    EXPECT_EQ(r.dx_cells, 0) << trial;
    EXPECT_NEAR(r.pose.y(), scan_pose.y(), 0.051) << trial;
    EXPECT_NEAR(r.pose.theta(), scan_pose.theta(), 0.0076) << trial;
  }
}

// In a room every direction is constrained: the prior does not stop a true offset of up to
// 0.1 m (ten prior sigmas) from being found.
TEST(MapCorrelatorTest, PriorStillRecoversAConstrainedOffset) {
  const testing::SegmentWorld world = testing::SegmentWorld::Office();
  const testing::RangeFinderSpec spec;
  OccupancyGrid grid(OccupancyGridOptions{});
  const Pose2 truth(6.0, 1.5, 0.1);
  RandomEngine rng(3);
  for (int i = 0; i < 3; ++i) grid.InsertScan(world.Scan(truth, Time{}, spec, &rng), truth);
  LikelihoodField field(LikelihoodFieldOptions{0.08, 0.9, 0.1, 0.0f, 3.0});
  field.Update(grid, Eigen::AlignedBox2d(Eigen::Vector2d(-5, -5), Eigen::Vector2d(25, 17)));
  const std::vector<Eigen::Vector2d> points =
      ScanToBasePoints(world.Scan(truth, Time{}, spec, &rng), ScanPointsOptions{});
  const MapCorrelator correlator(CorridorSearch());
  for (int trial = 0; trial < 10; ++trial) {
    const double dy = 2.0 * Uniform01(rng) - 1.0;  // y drawn first, as in Uniform3
    const double dx = 2.0 * Uniform01(rng) - 1.0;
    const Pose2 start(truth.x() + 0.1 * dx, truth.y() + 0.1 * dy, truth.theta());
    const CorrelationResult r = correlator.Correlate(field.view(), points, start);
    EXPECT_NEAR(r.pose.x(), truth.x(), 0.051) << trial;
    EXPECT_NEAR(r.pose.y(), truth.y(), 0.051) << trial;
  }
}

TEST(MapCorrelatorTest, NearTiesWithTheCentreStayPut) {
  // A raster that rises by 0.1 per cell in x: the best shift gains 0.4 per point.
  std::vector<float> ramp(100 * 100);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 100; ++x)
      ramp[static_cast<std::size_t>(y * 100 + x)] = 0.1f * static_cast<float>(x);
  }
  const GridView view{ramp.data(), 100, 100, Eigen::Vector2d::Zero(), 0.1};
  const std::vector<Eigen::Vector2d> points = {{1.0, 0.0}, {0.0, 1.0}};
  MapCorrelatorOptions options;
  options.value = CorrelationValue::kRawValue;
  options.min_shift_gain = 1.0f;  // two points gain 0.8 in all
  EXPECT_EQ(MapCorrelator(options).Correlate(view, points, Pose2(5.0, 5.0, 0.0)).dx_cells, 0);
  options.min_shift_gain = 0.5f;
  EXPECT_EQ(MapCorrelator(options).Correlate(view, points, Pose2(5.0, 5.0, 0.0)).dx_cells, 4);
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
  EXPECT_THAT(options.Validate(),
              ::testing::ElementsAre("xy_half_width_cells = -1; must be in [0, 15]",
                                     "yaw_step_rad = 0; must be > 0 when yaw_half_steps > 0"));
  options = MapCorrelatorOptions{};
  options.prior_sigma_xy_m = -0.1;
  options.min_shift_gain = -1.0f;
  EXPECT_THAT(options.Validate(), ::testing::ElementsAre("prior_sigma_xy_m = -0.1; must be >= 0",
                                                         "min_shift_gain = -1; must be >= 0"));
}

// Property: the occupied-indicator correlation read from an OccupiedMask that follows a changing
// grid gives the float path's result and score table bit for bit; windows of 1 to 31 cells,
// yaw shifts, points inside, near and beyond the edges, more than 255 points.
TEST(MapCorrelatorTest, OccupiedMaskGivesTheFloatPathsResultBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  OccupancyGridOptions grid_options;
  grid_options.resolution_m = 0.05;
  grid_options.grow_margin_m = 0.2;
  OccupancyGrid grid(grid_options);
  OccupiedMask mask(0.0f);
  LaserScan scan;
  scan.angle_min_rad = -3.1;
  scan.angle_increment_rad = 6.2 / 400;
  scan.range_min_m = 0.1;
  scan.range_max_m = 3.0;
  for (int round = 0; round < 30; ++round) {
    scan.ranges_m.clear();
    for (int i = 0; i < 400; ++i) scan.ranges_m.push_back(static_cast<float>(1.5 + 1.4 * u(rng)));
    const double theta = 3.0 * u(rng);  // drawn last component first, as in Uniform3
    const double y = 0.8 * u(rng);
    const Pose2 pose(0.8 * round * u(rng) / 10.0, y, theta);
    grid.InsertScan(scan, pose);
    mask.Follow(grid);
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < 300 + 20 * round; ++i) {
      const double py = 2.5 * u(rng);
      points.emplace_back(2.5 * u(rng), py);
    }
    MapCorrelatorOptions options;
    options.xy_half_width_cells = round % 16;
    options.yaw_half_steps = round % 3;
    options.yaw_step_rad = 0.01;
    options.prior_sigma_xy_m = round % 2 == 0 ? 0.0 : 0.1;
    const MapCorrelator correlator(options);
    std::vector<float> float_table, mask_table;
    // The mask path reads no values from the view: its lattice is enough.
    const CorrelationResult a =
        correlator.Correlate(DenseGrid(grid).view, points, pose, &float_table);
    const CorrelationResult b =
        correlator.Correlate(GridView::LatticeOf(grid), mask, points, pose, &mask_table);
    ASSERT_EQ(float_table.size(), mask_table.size());
    ASSERT_EQ(std::memcmp(float_table.data(), mask_table.data(), float_table.size() * 4), 0)
        << round;
    EXPECT_EQ(a.score, b.score);
    EXPECT_EQ(a.pose, b.pose);
    EXPECT_EQ(a.points_used, b.points_used);
    EXPECT_GT(*std::max_element(mask_table.begin(), mask_table.end()), 0.0f) << round;
  }
  // More than 255 points on walls for one shift: the byte counters must not wrap.
  for (int x = 0; x < grid.width(); ++x) {
    for (int y = 0; y < grid.height(); ++y) grid.Set({x, y}, 1.0f);
  }
  mask.Follow(grid);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 700; ++i) points.emplace_back(i % 2 == 0 ? 0.3 : 0.5, 0.2);
  const MapCorrelator correlator(MapCorrelatorOptions{});
  const CorrelationResult a = correlator.Correlate(DenseGrid(grid).view, points, Pose2());
  const CorrelationResult b =
      correlator.Correlate(GridView::LatticeOf(grid), mask, points, Pose2());
  EXPECT_EQ(a.score, 700.0f);
  EXPECT_EQ(b.score, 700.0f);
}

}  // namespace
}  // namespace slamrig::slam
