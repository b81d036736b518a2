#include "slam/grid/see_through.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "slam/grid/occupancy_grid.h"
#include "slam/grid/tiled_grid.h"

namespace slamrig::slam {
namespace {

// The room [0, kWidth] x [0, kHeight], scanned by a 360-beam lidar at the base.
constexpr double kWidth = 8.0;
constexpr double kHeight = 6.0;

// The distance from `p` along `direction` to the room's wall (p inside the room).
double RangeToWall(const Eigen::Vector2d& p, const Eigen::Vector2d& direction) {
  double range = std::numeric_limits<double>::infinity();
  if (direction.x() > 1e-12) range = std::min(range, (kWidth - p.x()) / direction.x());
  if (direction.x() < -1e-12) range = std::min(range, -p.x() / direction.x());
  if (direction.y() > 1e-12) range = std::min(range, (kHeight - p.y()) / direction.y());
  if (direction.y() < -1e-12) range = std::min(range, -p.y() / direction.y());
  return range;
}

// The scan the room returns at `truth`.
LaserScan RoomScan(const Pose2& truth) {
  LaserScan scan;
  scan.angle_min_rad = -std::numbers::pi;
  scan.angle_increment_rad = 2.0 * std::numbers::pi / 360.0;
  scan.range_min_m = 0.1;
  scan.range_max_m = 30.0;
  for (int i = 0; i < 360; ++i) {
    const double angle = truth.theta() + scan.BeamAngle(static_cast<std::size_t>(i));
    scan.ranges_m.push_back(static_cast<float>(
        RangeToWall(truth.translation(), Eigen::Vector2d(std::cos(angle), std::sin(angle)))));
  }
  return scan;
}

OccupancyGridOptions GridOptions() {
  OccupancyGridOptions options;
  options.resolution_m = 0.05;
  options.max_range_m = 30.0;
  return options;
}

// A pose drawn x, then y, then yaw (one draw per statement: a fixed order).
Pose2 DrawPose(std::mt19937& rng, std::uniform_real_distribution<double>& x,
               std::uniform_real_distribution<double>& y,
               std::uniform_real_distribution<double>& yaw) {
  const double px = x(rng);
  const double py = y(rng);
  return Pose2(px, py, yaw(rng));
}

// The room mapped from 20 poses inside it.
template <typename Grid>
void MapTheRoom(Grid* map) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(1.5, kWidth - 1.5), y(1.5, kHeight - 1.5), yaw(-3, 3);
  for (int i = 0; i < 20; ++i) {
    const Pose2 pose = DrawPose(rng, x, y, yaw);
    map->InsertScan(RoomScan(pose), pose);
  }
}

// Every beam_stride-th return (all beams return here), of those at least min_range_m long.
int LongRays(const LaserScan& scan, const SeeThroughOptions& options) {
  int rays = 0;
  for (std::size_t b = 0; b < scan.ranges_m.size(); b += options.beam_stride) {
    rays += scan.ranges_m[b] >= options.min_range_m;
  }
  return rays;
}

TEST(SeeThroughTest, AScanAgreesWithTheMapOfItsOwnRoom) {
  OccupancyGrid map(GridOptions());
  MapTheRoom(&map);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(1.0, kWidth - 1.0), y(1.0, kHeight - 1.0), yaw(-3, 3);
  for (int i = 0; i < 50; ++i) {
    const Pose2 pose = DrawPose(rng, x, y, yaw);
    const LaserScan scan = RoomScan(pose);
    const SeeThrough result = CountSeeThrough(map, scan, pose, std::nullopt, {});
    EXPECT_EQ(result.rays, LongRays(scan, SeeThroughOptions{})) << i;
    EXPECT_LE(result.crossing, 2) << i;
  }
}

// A scan placed 1.5 m east of where it was taken (a revisit the filter put beside the first
// visit): its rays to the east end 1.5 m beyond the mapped east wall and cross it when their
// traced part (all but end_margin_m) reaches past it; no other ray crosses a wall. Counted
// against that geometry on both grid types.
template <typename Grid>
void CheckAMisplacedScanCrossesTheWallsItShouldHaveEnded(Grid* map) {
  MapTheRoom(map);
  const SeeThroughOptions options;
  std::mt19937 rng(13);
  // Placed inside the room too, at least 0.5 m from the east wall.
  std::uniform_real_distribution<double> x(1.0, kWidth - 2.0), y(1.0, kHeight - 1.0), yaw(-3, 3);
  int compared = 0;
  for (int i = 0; i < 50; ++i) {
    const Pose2 truth = DrawPose(rng, x, y, yaw);
    const Pose2 placed(truth.x() + 1.5, truth.y(), truth.theta());
    const LaserScan scan = RoomScan(truth);
    int expected = 0, ambiguous = 0, rays = 0;
    for (std::size_t b = 0; b < scan.ranges_m.size(); b += 2) {
      if (scan.ranges_m[b] < options.min_range_m) continue;
      ++rays;
      const double angle = truth.theta() + scan.BeamAngle(b);
      const double traced = scan.ranges_m[b] - options.end_margin_m;
      const double reach_x = placed.x() + traced * std::cos(angle);  // the traced end's x
      // Crosses the east wall (x = kWidth) within the room's height; a cell either side of the
      // wall or of its corners is left to the lattice.
      const double y_at_wall = placed.y() + (kWidth - placed.x()) * std::tan(angle);
      const bool east = std::cos(angle) > 0;
      const bool near_wall = std::abs(reach_x - kWidth) < 0.1;
      const bool near_corner = std::min(std::abs(y_at_wall), std::abs(y_at_wall - kHeight)) < 0.1;
      if (east && (near_wall || near_corner)) {
        ++ambiguous;
        continue;
      }
      expected += east && reach_x > kWidth && y_at_wall > 0 && y_at_wall < kHeight;
    }
    const SeeThrough result = CountSeeThrough(*map, scan, placed, std::nullopt, options);
    EXPECT_EQ(result.rays, rays) << i;
    EXPECT_GE(result.crossing, expected) << i;
    EXPECT_LE(result.crossing, expected + ambiguous) << i;
    compared += expected > 10;
  }
  EXPECT_GT(compared, 25);  // most placements see through the wall with many rays
}

TEST(SeeThroughTest, AMisplacedScanCrossesTheWallsItShouldHaveEnded) {
  OccupancyGrid grid(GridOptions());
  CheckAMisplacedScanCrossesTheWallsItShouldHaveEnded(&grid);
  TiledGrid tiled(GridOptions());
  CheckAMisplacedScanCrossesTheWallsItShouldHaveEnded(&tiled);
}

TEST(SeeThroughTest, AWallSeenOnceIsNotYetAWall) {
  OccupancyGrid map(GridOptions());
  const Pose2 pose(4.0, 3.0, 0.0);
  map.InsertScan(RoomScan(pose), pose);  // every wall cell once: one hit's log-odds
  const Pose2 placed(5.5, 3.0, 0.0);
  EXPECT_EQ(CountSeeThrough(map, RoomScan(pose), placed, std::nullopt, {}).crossing, 0);
}

}  // namespace
}  // namespace slamrig::slam
