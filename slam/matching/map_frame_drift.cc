#include "slam/matching/map_frame_drift.h"

#include <Eigen/Dense>
#include <algorithm>
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

namespace slamrig::slam {
namespace {

// An error (x, y, yaw) of a rigid motion about the origin, as the same motion's error about `xy`
// (CovarianceAtRobot's lever from the origin).
Eigen::Matrix3d LeverFromOrigin(const Eigen::Vector2d& xy) {
  Eigen::Matrix3d g = Eigen::Matrix3d::Identity();
  g(0, 2) = -xy.y();
  g(1, 2) = xy.x();
  return g;
}

// The Moore-Penrose inverse of a symmetric positive semi-definite `s`, its eigenvalues below
// 1e-12 of the largest taken as zero (a frame that is known exactly, as the first keyframe's).
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& s) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s);
  const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(s.rows());
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    if (largest > 0.0 && eig.eigenvalues()(i) > 1e-12 * largest) {
      inverse(i) = 1.0 / eig.eigenvalues()(i);
    }
  }
  return eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

Eigen::Matrix3d KeyframeErrors::Join(int id, const Eigen::Matrix3d& r,
                                     std::span<const KeyframeShareChange> changes,
                                     const Eigen::Vector2d& robot_xy, bool placed) {
  // A keyframe that joined unseen (before the filter followed the map) is taken as the frame's
  // definition: no error.
  for (const KeyframeShareChange& c : changes) {
    if (c.id == id || std::find(ids_.begin(), ids_.end(), c.id) != ids_.end()) continue;
    ids_.push_back(c.id);
    covariance_.conservativeResize(3 * size(), 3 * size());
    covariance_.rightCols(3).setZero();
    covariance_.bottomRows(3).setZero();
  }
  const Eigen::Index k = static_cast<Eigen::Index>(ids_.size());
  const Eigen::Index n = 3 * (k + 1);
  const Eigen::Matrix3d g = LeverFromOrigin(robot_xy);
  // The errors of the keyframes in the map and of the new one, about the robot.
  Eigen::MatrixXd joint = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index a = 0; a < k; ++a) {
    for (Eigen::Index b = 0; b < k; ++b) {
      joint.block<3, 3>(3 * a, 3 * b) = g * covariance_.block<3, 3>(3 * a, 3 * b) * g.transpose();
    }
  }
  Eigen::MatrixXd before = Eigen::MatrixXd::Zero(3, n);
  Eigen::MatrixXd after = Eigen::MatrixXd::Zero(3, n);
  std::vector<bool> stays(static_cast<std::size_t>(k + 1), false);
  stays.back() = true;
  for (const KeyframeShareChange& c : changes) {
    Eigen::Index block = k;
    if (c.id != id) {
      block = std::find(ids_.begin(), ids_.end(), c.id) - ids_.begin();
      stays[static_cast<std::size_t>(block)] = c.stays;
    }
    before.middleCols<3>(3 * block) = c.before;
    after.middleCols<3>(3 * block) = c.after;
  }
  // The new keyframe's error: the frame's then plus its match's.
  const Eigen::MatrixXd frame = before.leftCols(3 * k);
  const Eigen::MatrixXd frame_cross = frame * joint.topLeftCorner(3 * k, 3 * k);
  joint.block(3 * k, 0, 3, 3 * k) = frame_cross;
  joint.block(0, 3 * k, 3 * k, 3) = frame_cross.transpose();
  joint.block<3, 3>(3 * k, 3 * k) = frame_cross * frame.transpose() + r;

  // The frame's move, given the frame before (and the new keyframe's error).
  const Eigen::MatrixXd move = after - before;
  Eigen::MatrixXd given = Eigen::MatrixXd::Zero(placed ? 6 : 3, n);
  given.topRows(3) = before;
  if (placed) given.block<3, 3>(3, 3 * k).setIdentity();
  const Eigen::MatrixXd cross = move * joint * given.transpose();
  const Eigen::MatrixXd conditional =
      move * joint * move.transpose() -
      cross * PseudoInverse(given * joint * given.transpose()) * cross.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(
      Eigen::Matrix3d(0.5 * (conditional + conditional.transpose())));
  const Eigen::Matrix3d q = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
                            eig.eigenvectors().transpose();

  // Those that leave are marginalised out (their rows dropped); back about the origin.
  const Eigen::Matrix3d g_inverse = LeverFromOrigin(-robot_xy);
  std::vector<Eigen::Index> kept;
  std::vector<int> ids;
  for (Eigen::Index a = 0; a <= k; ++a) {
    if (!stays[static_cast<std::size_t>(a)]) continue;
    kept.push_back(a);
    ids.push_back(a == k ? id : ids_[static_cast<std::size_t>(a)]);
  }
  const auto m = static_cast<Eigen::Index>(kept.size());
  covariance_.setZero(3 * m, 3 * m);
  for (Eigen::Index a = 0; a < m; ++a) {
    for (Eigen::Index b = 0; b < m; ++b) {
      covariance_.block<3, 3>(3 * a, 3 * b) =
          g_inverse * joint.block<3, 3>(3 * kept[a], 3 * kept[b]) * g_inverse.transpose();
    }
  }
  ids_ = std::move(ids);
  return q;
}

}  // namespace slamrig::slam
