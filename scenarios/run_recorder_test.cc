#include "scenarios/run_recorder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "slam/types/random_stream.h"

namespace slamrig::scenario {
namespace {

// The percent of every observed cell is round(100 p) of its log-odds, computed here with exp;
// unknown cells are -1; the message covers exactly the box of observed cells, placed by the
// frame transform.
TEST(ToRosGridTest, PercentsBoxAndOriginAgainstDirectComputation) {
  slam::OccupancyGridOptions options;
  options.resolution_m = 0.1;
  slam::OccupancyGrid grid(options, Eigen::Vector2d(-2.0, 1.0), 60, 40);
  RandomStream random(3, "grid");
  // Observed cells inside the box x in [7, 41], y in [5, 30]; corners pin the box.
  for (int i = 0; i < 2000; ++i) {
    const int x = 7 + static_cast<int>(35.0 * random.Uniform());
    const int y = 5 + static_cast<int>(26.0 * random.Uniform());
    grid.Set({std::min(x, 41), std::min(y, 30)},
             static_cast<float>(-6.0 + 12.0 * random.Uniform()));
  }
  grid.Set({7, 5}, 0.5f);
  grid.Set({41, 30}, -0.5f);
  // Values exactly on and next to rounding boundaries.
  for (int k = 0; k < 100; ++k) {
    const double p = (k + 0.5) / 100.0;
    const float l = static_cast<float>(std::log(p / (1.0 - p)));
    grid.Set({8 + k % 30, 6 + k / 30}, l);
    grid.Set({8 + k % 30, 10 + k / 30}, std::nextafter(l, -10.0f));
  }
  const Pose2 frame_from_grid(1.0, -2.0, 0.3);
  const slam::RosOccupancyGrid g = ToRosGrid(grid, Time{5}, "pf/map", frame_from_grid);
  EXPECT_EQ(g.frame_id, "pf/map");
  EXPECT_EQ(g.width, 35u);
  EXPECT_EQ(g.height, 26u);
  const Pose2 want = frame_from_grid * Pose2(-2.0 + 0.7, 1.0 + 0.5, 0.0);
  EXPECT_NEAR(g.origin.x(), want.x(), 1e-12);
  EXPECT_NEAR(g.origin.y(), want.y(), 1e-12);
  EXPECT_NEAR(g.origin.theta(), 0.3, 1e-12);
  ASSERT_EQ(g.data.size(), 35u * 26u);
  int observed = 0;
  for (int y = 0; y < 26; ++y) {
    for (int x = 0; x < 35; ++x) {
      const float l = grid.LogOdds({x + 7, y + 5});
      const int got = g.data[static_cast<std::size_t>(y) * 35 + x];
      if (l == 0.0f) {
        EXPECT_EQ(got, -1);
        continue;
      }
      ++observed;
      const double p = 1.0 / (1.0 + std::exp(-static_cast<double>(l)));
      const double scaled = 100.0 * p;
      // At an exact half the direct computation's own rounding may go either way.
      if (std::abs(scaled - std::floor(scaled) - 0.5) > 1e-6) {
        EXPECT_EQ(got, std::lround(scaled)) << "cell " << x << ", " << y << " log-odds " << l;
      } else {
        EXPECT_NEAR(got, scaled, 0.5 + 1e-6);
      }
    }
  }
  EXPECT_GT(observed, 500);
}

TEST(ToRosGridTest, NothingObservedIsOneUnknownCell) {
  slam::OccupancyGrid grid(slam::OccupancyGridOptions{}, Eigen::Vector2d(0.0, 0.0), 10, 10);
  const slam::RosOccupancyGrid g = ToRosGrid(grid, Time{0}, "map", Pose2());
  EXPECT_EQ(g.width, 1u);
  EXPECT_EQ(g.height, 1u);
  ASSERT_EQ(g.data.size(), 1u);
  EXPECT_EQ(g.data[0], -1);
}

// A recorder destroyed before Finish() (an exception, an interrupt) leaves nothing: neither the
// partial file nor the folder it made.
TEST(RunRecorderTest, UnfinishedRecordingLeavesNothing) {
  const std::string dir = testing::TempDir() + "/recorder_unfinished/report";
  std::filesystem::remove_all(dir);
  {
    RunRecorder recorder(dir + "/run.mcap", {"pf"}, RecorderOptions{});
    recorder.Truth(Time{1000}, Pose2(1.0, 2.0, 0.5));
    EXPECT_TRUE(std::filesystem::exists(dir + "/run.mcap.partial"));
  }
  EXPECT_FALSE(std::filesystem::exists(dir));
}

}  // namespace
}  // namespace slamrig::scenario
