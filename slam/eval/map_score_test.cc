#include "slam/eval/map_score.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace slamrig::slam {
namespace {

// A 0.1 m grid with an L-shaped wall, optionally shifted by whole cells and moved by a pose.
OccupancyGrid Wall(int shift_cells, const Pose2& world_from_wall = Pose2()) {
  OccupancyGridOptions options;
  options.resolution_m = 0.1;
  OccupancyGrid grid(options);
  grid.EnsureContains(Eigen::AlignedBox2d(Eigen::Vector2d(-1, -1), Eigen::Vector2d(6, 6)));
  for (int i = 0; i < 40; ++i) {
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.05 + 0.1 * i, 0.05 + 0.1 * shift_cells),
                                     Eigen::Vector2d(0.05, 0.05 + 0.1 * i + 0.1 * shift_cells)}) {
      grid.Set(grid.WorldToCell(world_from_wall * p), 3.0f);
    }
  }
  return grid;
}

TEST(MapScoreTest, ToleranceOfOneCell) {
  const OccupancyGrid truth = Wall(0);
  const MapScore same = ScoreMap(Wall(0), Pose2(), truth);
  EXPECT_EQ(same.estimate_occupied, 79);
  EXPECT_DOUBLE_EQ(same.f1, 1.0);
  EXPECT_DOUBLE_EQ(same.iou, 1.0);
  EXPECT_DOUBLE_EQ(ScoreMap(Wall(1), Pose2(), truth).f1, 1.0);
  MapScoreOptions exact;
  exact.tolerance_cells = 0;
  // Shifted up by a cell: only the vertical wall's cells still coincide.
  const MapScore shifted = ScoreMap(Wall(1), Pose2(), truth, exact);
  EXPECT_EQ(shifted.estimate_matched, 39);
  EXPECT_NEAR(shifted.precision, 39.0 / 79.0, 1e-12);
  EXPECT_NEAR(shifted.iou, shifted.f1 / (2 - shifted.f1), 1e-12);
}

TEST(MapScoreTest, AlignmentMovesTheEstimateIntoTheTruthFrame) {
  const Pose2 motion(1.0, 2.0, 0.5);
  const OccupancyGrid moved = Wall(0, motion);
  const OccupancyGrid truth = Wall(0);
  EXPECT_LT(ScoreMap(moved, Pose2(), truth).f1, 0.1);
  EXPECT_GT(ScoreMap(moved, motion.Inverse(), truth).f1, 0.95);
}

}  // namespace
}  // namespace slamrig::slam
