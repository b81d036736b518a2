#include "slam/matching/map_frame_drift.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <unordered_set>

#include "slam/matching/point_kd_tree.h"
#include "slam/types/check.h"

namespace slamrig::slam {

LocalMapPoints ComposeLocalMap(std::span<const std::vector<Eigen::Vector2d>> keyframes,
                               double voxel_m) {
  LocalMapPoints map;
  std::unordered_set<std::int64_t> seen;
  for (std::size_t j = keyframes.size(); j-- > 0;) {
    for (const Eigen::Vector2d& p : keyframes[j]) {
      if (voxel_m > 0.0) {
        const auto vx = static_cast<std::int64_t>(std::floor(p.x() / voxel_m));
        const auto vy = static_cast<std::int64_t>(std::floor(p.y() / voxel_m));
        if (!seen.insert(vx * 4000003 + vy).second) continue;
      }
      map.points.push_back(p);
      map.keyframe.push_back(static_cast<int>(j));
    }
  }
  return map;
}

std::vector<Eigen::Matrix3d> KeyframeInformations(
    const LocalMapPoints& map, std::span<const Eigen::Vector2d> normals, int keyframes,
    std::span<const Eigen::Vector2d> scan, double max_distance_m, const Eigen::Vector2d& robot_xy) {
  std::vector<Eigen::Matrix3d> informations(static_cast<std::size_t>(keyframes),
                                            Eigen::Matrix3d::Zero());
  if (normals.empty() || map.points.empty()) return informations;
  SLAMRIG_CHECK(normals.size() == map.points.size(), "one normal per point");
  const PointKdTree tree(map.points);
  for (const Eigen::Vector2d& q : scan) {
    std::uint32_t i = 0;
    double distance2 = 0.0;
    if (!tree.Nearest(q, &i, &distance2) || distance2 > max_distance_m * max_distance_m) continue;
    informations[static_cast<std::size_t>(map.keyframe[i])] +=
        PointToLineInformation(std::span(&map.points[i], 1), normals.subspan(i, 1), robot_xy);
  }
  return informations;
}

Eigen::Matrix3d PointToLineInformation(std::span<const Eigen::Vector2d> points,
                                       std::span<const Eigen::Vector2d> normals,
                                       const Eigen::Vector2d& robot_xy) {
  SLAMRIG_CHECK(points.size() == normals.size(), "one normal per point");
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d& n = normals[i];
    if (n.squaredNorm() == 0.0) continue;
    const Eigen::Vector2d lever = points[i] - robot_xy;
    const Eigen::Vector3d j(n.x(), n.y(), n.x() * -lever.y() + n.y() * lever.x());
    h.noalias() += j * j.transpose();
  }
  return h;
}

std::vector<Eigen::Matrix3d> FrameWeights(std::span<const Eigen::Matrix3d> informations) {
  Eigen::Matrix3d total = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& h : informations) total += h;
  std::vector<Eigen::Matrix3d> weights(informations.size(), Eigen::Matrix3d::Zero());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(total);
  const double largest = eig.eigenvalues().maxCoeff();
  if (!(largest > 0.0)) return weights;
  const Eigen::Vector3d inverse = eig.eigenvalues().cwiseMax(1e-9 * largest).cwiseInverse();
  const Eigen::Matrix3d total_inverse =
      eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  for (std::size_t j = 0; j < informations.size(); ++j) {
    weights[j] = total_inverse * informations[j];
  }
  return weights;
}

Eigen::Matrix3d CovarianceAtRobot(const Eigen::Matrix3d& covariance,
                                  const Eigen::Vector2d& keyframe_xy,
                                  const Eigen::Vector2d& robot_xy) {
  // A pose error (dx, dy, dyaw) at the keyframe is the rigid motion that also moves the robot's
  // pose by (dx - dyaw (robot - keyframe)_y, dy + dyaw (robot - keyframe)_x, dyaw).
  const Eigen::Vector2d lever = robot_xy - keyframe_xy;
  Eigen::Matrix3d g = Eigen::Matrix3d::Identity();
  g(0, 2) = -lever.y();
  g(1, 2) = lever.x();
  return g * covariance * g.transpose();
}

Eigen::Matrix3d FrameDriftCovariance(std::span<const KeyframeShare> shares) {
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  for (const KeyframeShare& s : shares) {
    const Eigen::Matrix3d change = s.after - s.before;
    q.noalias() += change * s.covariance * change.transpose();
  }
  return 0.5 * (q + q.transpose());
}

}  // namespace slamrig::slam
