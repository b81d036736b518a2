#pragma once

#include <cstdint>
#include <vector>

#include "slam/graph/pose_graph.h"

namespace slamrig::slam::testing {

/// How RandomPoseGraph() builds a graph with known truth.
struct RandomPoseGraphOptions {
  int num_poses = 50;
  /// Each pose i >= 3 gets a loop closure to a random earlier pose with this probability.
  double loop_closure_probability = 0.3;
  /// Standard deviations of the measurement noise (0 gives exact measurements).
  double sigma_xy_m = 0.05;
  double sigma_theta_rad = 0.01;
  std::uint64_t seed = 1;
};

/// A graph and the true poses it was measured from.
struct RandomPoseGraph {
  /// Vertices at the true poses (vertex 0 at the origin), edges measured with Gaussian noise
  /// (information = inverse of the noise covariance): odometry i -> i+1 and loop closures.
  PoseGraph graph;
  std::vector<Pose2> truth;
};

/// A random walk (steps of about 1 m, turns up to 1 rad) measured with seeded noise.
RandomPoseGraph MakeRandomPoseGraph(const RandomPoseGraphOptions& options);

}  // namespace slamrig::slam::testing
