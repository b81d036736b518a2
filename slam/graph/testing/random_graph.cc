#include "slam/graph/testing/random_graph.h"

#include <random>

namespace slamrig::slam::testing {

RandomPoseGraph MakeRandomPoseGraph(const RandomPoseGraphOptions& options) {
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> step(0.5, 1.5), turn(-1.0, 1.0), unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  RandomPoseGraph out;
  Pose2 pose;
  for (int i = 0; i < options.num_poses; ++i) {
    if (i > 0) {
      // Sequenced draws, the last coordinate first: the order the graphs were generated in.
      const double yaw = turn(rng), y = 0.2 * turn(rng);
      pose = pose * Pose2(step(rng), y, yaw);
    }
    out.truth.push_back(pose);
    out.graph.AddVertex(i, pose);
  }
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  information.diagonal() << 1.0, 1.0, 1.0;
  if (options.sigma_xy_m > 0.0 && options.sigma_theta_rad > 0.0) {
    information.diagonal() << 1.0 / (options.sigma_xy_m * options.sigma_xy_m),
        1.0 / (options.sigma_xy_m * options.sigma_xy_m),
        1.0 / (options.sigma_theta_rad * options.sigma_theta_rad);
  }
  const auto measure = [&](int from, int to, EdgeKind kind) {
    const double yaw = options.sigma_theta_rad * normal(rng);
    const double y = options.sigma_xy_m * normal(rng);
    const Pose2 noise(options.sigma_xy_m * normal(rng), y, yaw);
    out.graph.AddEdge({.from = from,
                       .to = to,
                       .measurement = out.truth[from].Between(out.truth[to]) * noise,
                       .information = information,
                       .kind = kind});
  };
  for (int i = 0; i + 1 < options.num_poses; ++i) measure(i, i + 1, EdgeKind::kOdometry);
  for (int i = 3; i < options.num_poses; ++i) {
    if (unit(rng) < options.loop_closure_probability) {
      const int j = std::uniform_int_distribution<int>(0, i - 2)(rng);
      measure(j, i, EdgeKind::kLoopClosure);
    }
  }
  return out;
}

}  // namespace slamrig::slam::testing
