// Where the occupied boundary of a straight wall ends up under noisy ranges: the mapping bias
// behind the office pf's too-wide corridors (issue 11).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "slam/grid/occupancy_grid.h"

namespace slamrig::slam {
namespace {

struct WallStats {
  double centroid_m = 0.0;  // mean over rows of the occupied cells' centre x, minus the wall's x
  double front_m = 0.0;     // mean over rows of the first occupied cell's centre x, minus the wall
  double thickness_cells = 0.0;  // mean number of occupied cells per row
};

// A robot drives along a wall at x = wall_x (the sensor side is x < wall_x), from y = -2 to 2 at
// `distance` from it, scanning a Hokuyo-like fan (1081 beams over 270 degrees) whose beams that
// point at the wall return the true range plus N(0, sigma); the others return nothing usable.
// Statistics over the rows |y| < 1, where the wall was seen from every side.
WallStats MapWall(const OccupancyGridOptions& options, double wall_x, double distance, double sigma,
                  std::uint64_t seed) {
  OccupancyGrid grid(options);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  LaserScan scan;
  scan.angle_min_rad = -0.75 * M_PI;
  scan.angle_increment_rad = 1.5 * M_PI / 1080;
  scan.range_min_m = 0.1;
  scan.range_max_m = 30.0;
  scan.ranges_m.resize(1081);
  for (double y = -2.0; y <= 2.0; y += 0.05) {
    const Pose2 pose(wall_x - distance, y, 0.3 * std::sin(3.0 * y));
    for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
      const double a = pose.theta() + scan.BeamAngle(i);
      const double c = std::cos(a);
      const double hit_y = y + distance * std::tan(a);
      scan.ranges_m[i] =
          c > 0.2 && std::abs(hit_y) < 3.0 ? static_cast<float>(distance / c + noise(rng)) : 0.0f;
    }
    grid.InsertScan(scan, pose);
  }
  WallStats s;
  int rows = 0;
  const double res = options.resolution_m;
  for (double y = -1.0 + 0.5 * res; y < 1.0; y += res) {
    double sum = 0.0;
    int n = 0;
    double front = 0.0;
    for (double x = wall_x - 0.3; x < wall_x + 0.3; x += res) {
      const Eigen::Array2i c = grid.WorldToCell({x, y});
      if (grid.LogOdds(c) <= 0.0f) continue;
      const double cx = grid.CellCenter(c).x();
      if (n == 0) front = cx;
      sum += cx;
      ++n;
    }
    if (n == 0) continue;
    ++rows;
    s.centroid_m += sum / n - wall_x;
    s.front_m += front - wall_x;
    s.thickness_cells += n;
  }
  if (rows > 0) {
    s.centroid_m /= rows;
    s.front_m /= rows;
    s.thickness_cells /= rows;
  }
  return s;
}

// Averaged over walls at 8 sub-cell offsets, so that cell quantisation averages out.
WallStats MeanOverOffsets(const OccupancyGridOptions& options, double distance, double sigma) {
  WallStats mean;
  const int n = 8;
  for (int k = 0; k < n; ++k) {
    const double wall_x = 2.0 + (k + 0.5) / n * options.resolution_m;
    const WallStats s = MapWall(options, wall_x, distance, sigma, 7 + k);
    mean.centroid_m += s.centroid_m / n;
    mean.front_m += s.front_m / n;
    mean.thickness_cells += s.thickness_cells / n;
  }
  return mean;
}

// The mechanism: with the default writer the wall's occupied cells sit behind its surface by most
// of a sigma; with exact ranges, or with no free evidence at all (so that nothing clears cells in
// front of the wall either), they centre on it.
TEST(WallBiasTest, DefaultWriterPutsWallsBehindTheSurface) {
  OccupancyGridOptions o;
  o.resolution_m = 0.025;
  const double sigma = 0.01;
  const WallStats noisy = MeanOverOffsets(o, 1.0, sigma);
  EXPECT_GT(noisy.centroid_m, 0.6 * sigma);
  EXPECT_GT(noisy.thickness_cells, 2.0);
  EXPECT_NEAR(MeanOverOffsets(o, 1.0, 0.0).centroid_m, 0.0, 1e-9);
  OccupancyGridOptions hits_only = o;
  hits_only.miss_log_odds = -1e-6f;
  EXPECT_NEAR(MeanOverOffsets(hits_only, 1.0, sigma).centroid_m, 0.0, 0.15 * sigma);
}

// The fix: hits behind a wall cell within the noise mark the wall cell.
TEST(WallBiasTest, HitWindowCentresWallsOnTheSurface) {
  for (const double res : {0.025, 0.05}) {
    for (const double sigma : {0.01, 0.02}) {
      for (const double distance : {0.5, 2.0}) {
        OccupancyGridOptions o;
        o.resolution_m = res;
        const double before = MeanOverOffsets(o, distance, sigma).centroid_m;
        o.range_stddev_m = sigma;
        const WallStats after = MeanOverOffsets(o, distance, sigma);
        SCOPED_TRACE(testing::Message()
                     << "res " << res << " sigma " << sigma << " distance " << distance
                     << " centroid " << before << " -> " << after.centroid_m);
        EXPECT_GT(before, 0.5 * sigma);
        EXPECT_LT(std::abs(after.centroid_m), 0.4 * sigma);
        EXPECT_LT(std::abs(after.centroid_m), 0.6 * before);
      }
    }
  }
}

}  // namespace
}  // namespace slamrig::slam
