#include "slam/fusion/landmark_extraction.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <random>

namespace slamrig::slam {
namespace {

struct Disc {
  Eigen::Vector2d center;
  double radius;
};

// Range along the ray from `origin` in direction `u` to the nearest disc or to the wall x = wall_x
// (infinity when it hits nothing).
double CastRay(const Eigen::Vector2d& origin, const Eigen::Vector2d& u,
               const std::vector<Disc>& discs, double wall_x) {
  double best = std::numeric_limits<double>::infinity();
  for (const Disc& d : discs) {
    const Eigen::Vector2d m = origin - d.center;
    const double b = m.dot(u);
    const double c = m.squaredNorm() - d.radius * d.radius;
    const double disc = b * b - c;
    if (disc < 0.0) continue;
    const double t = -b - std::sqrt(disc);
    if (t > 0.0) best = std::min(best, t);
  }
  if (u.x() > 1e-9) {
    const double t = (wall_x - origin.x()) / u.x();
    if (t > 0.0) best = std::min(best, t);
  }
  return best;
}

// A Hokuyo-like scan (0.25 degree steps, 1 cm noise) from a laser mounted 0.2 m ahead of
// base_link and turned by 0.1 rad, seeing three pillars of different radii in front of a wall.
LaserScan SyntheticScan(const std::vector<Disc>& discs, std::mt19937_64& rng) {
  LaserScan scan;
  scan.angle_min_rad = -2.35;
  scan.angle_increment_rad = 0.25 * M_PI / 180.0;
  scan.range_min_m = 0.1;
  scan.range_max_m = 30.0;
  scan.base_from_laser = Pose2(0.2, 0.0, 0.1);
  std::normal_distribution<double> noise(0.0, 0.01);
  const int beams = 1081;
  for (int i = 0; i < beams; ++i) {
    const double a = scan.base_from_laser.theta() + scan.BeamAngle(i);
    const double r = CastRay(scan.base_from_laser.translation(),
                             Eigen::Vector2d(std::cos(a), std::sin(a)), discs, 9.0);
    scan.ranges_m.push_back(std::isfinite(r) ? static_cast<float>(r + noise(rng))
                                             : static_cast<float>(scan.range_max_m));
  }
  return scan;
}

// The pillars' centres come back within a few noise widths (base_link frame, the mount applied),
// the wall makes no landmark, and the fit's range-bearing covariance is honest: with negligible
// floors the mean NEES over many scans is near its 2 degrees of freedom.
TEST(LandmarkExtractionTest, RecoversCircleCentresFromASyntheticScan) {
  const std::vector<Disc> discs = {{{4.0, 1.0}, 0.25}, {{6.0, -3.0}, 0.15}, {{2.5, -0.5}, 0.3}};
  std::mt19937_64 rng(3);
  LandmarkExtractionOptions options;
  options.range_sigma_floor_m = 1e-6;
  options.bearing_sigma_floor_rad = 1e-7;
  double nees_sum = 0.0;
  int seen = 0;
  const int trials = 50;
  for (int trial = 0; trial < trials; ++trial) {
    const std::vector<LandmarkObservation> found =
        ExtractLandmarks(SyntheticScan(discs, rng), options);
    ASSERT_EQ(found.size(), discs.size()) << trial;
    for (const LandmarkObservation& z : found) {
      int nearest = 0;
      for (int d = 1; d < static_cast<int>(discs.size()); ++d) {
        if ((discs[d].center - z.center_m).norm() < (discs[nearest].center - z.center_m).norm())
          nearest = d;
      }
      const Disc& truth = discs[nearest];
      EXPECT_LT((z.center_m - truth.center).norm(), 0.03) << trial;
      EXPECT_NEAR(z.radius_m, truth.radius, 0.03) << trial;
      EXPECT_NEAR(z.range_m, z.center_m.norm(), 1e-12);
      Eigen::Vector2d e(truth.center.norm() - z.range_m,
                        std::atan2(truth.center.y(), truth.center.x()) - z.bearing_rad);
      nees_sum += e.dot(z.covariance.inverse() * e);
      ++seen;
    }
  }
  EXPECT_GT(nees_sum / seen, 1.2);
  EXPECT_LT(nees_sum / seen, 3.5);
}

// A wall alone, or a wall with a square column's corner in front of it, makes no landmark.
TEST(LandmarkExtractionTest, WallsAndCornersAreNotLandmarks) {
  std::mt19937_64 rng(4);
  const LaserScan wall = SyntheticScan({}, rng);
  EXPECT_TRUE(ExtractLandmarks(wall, {}).empty());
  // A 0.5 m square column turned 45 degrees, its corner towards the laser.
  LaserScan scan = wall;
  const Eigen::Vector2d c(3.0, 0.0);
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const double a = scan.base_from_laser.theta() + scan.BeamAngle(i);
    const Eigen::Vector2d u(std::cos(a), std::sin(a));
    const Eigen::Vector2d o = scan.base_from_laser.translation();
    // The column's near faces: |x - cx| + |y - cy| = 0.354 (a diamond), first hit along the ray.
    for (double t = 0.1; t < scan.ranges_m[i]; t += 0.0005) {
      const Eigen::Vector2d p = o + t * u - c;
      if (std::abs(p.x()) + std::abs(p.y()) <= 0.354) {
        std::normal_distribution<double> noise(0.0, 0.01);
        scan.ranges_m[i] = static_cast<float>(t + noise(rng));
        break;
      }
    }
  }
  EXPECT_TRUE(ExtractLandmarks(scan, {}).empty());
}

TEST(LandmarkExtractionTest, ValidateNamesTheKeys) {
  LandmarkExtractionOptions o;
  o.min_points = 2;
  o.max_radius_m = 0.01;
  const std::vector<std::string> errors = o.Validate();
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].rfind("min_points = 2", 0), 0u) << errors[0];
  EXPECT_EQ(errors[1].rfind("max_radius_m = 0.01", 0), 0u) << errors[1];
}

}  // namespace
}  // namespace slamrig::slam
