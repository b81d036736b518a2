#include "slam/matching/map_frame_drift.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_set>

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

std::vector<Eigen::Matrix3d> KeyframeInformations(const LocalMapPoints& map,
                                                  const IcpMatcher& matcher, int keyframes,
                                                  std::span<const Eigen::Vector2d> scan,
                                                  const Eigen::Vector2d& robot_xy) {
  std::vector<Eigen::Matrix3d> informations(static_cast<std::size_t>(keyframes),
                                            Eigen::Matrix3d::Zero());
  if (!matcher.has_normals() || map.points.empty()) return informations;
  SLAMRIG_CHECK(matcher.reference().size() == map.points.size(), "one reference point per point");
  const double max_distance_m = matcher.options().max_correspondence_distance_m;
  for (const Eigen::Vector2d& q : scan) {
    std::uint32_t i = 0;
    double distance2 = 0.0;
    if (!matcher.tree().Nearest(q, &i, &distance2, max_distance_m * max_distance_m)) {
      continue;
    }
    const Eigen::Vector2d normal = matcher.Normal(i);
    informations[static_cast<std::size_t>(map.keyframe[i])] +=
        PointToLineInformation(std::span(&map.points[i], 1), std::span(&normal, 1), robot_xy);
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

Eigen::Matrix3d KeyframeErrors::See(std::span<const KeyframeShareOf> shares,
                                    const Eigen::Vector2d& robot_xy) {
  for (const KeyframeShareOf& s : shares) {
    if (std::find(ids_.begin(), ids_.end(), s.id) != ids_.end()) continue;
    ids_.push_back(s.id);
    covariance_.conservativeResize(3 * size(), 3 * size());
    covariance_.rightCols(3).setZero();
    covariance_.bottomRows(3).setZero();
  }
  const Eigen::Index n = 3 * size();
  const Eigen::Matrix3d g = LeverFromOrigin(robot_xy);
  const Eigen::Matrix3d g_inverse = LeverFromOrigin(-robot_xy);
  // The frame now and before as functions of the errors, about the origin.
  Eigen::MatrixXd now = Eigen::MatrixXd::Zero(3, n);
  std::vector<bool> in_map(ids_.size(), false);
  for (const KeyframeShareOf& s : shares) {
    const auto block = std::find(ids_.begin(), ids_.end(), s.id) - ids_.begin();
    now.middleCols<3>(3 * block) = g_inverse * s.share * g;
    in_map[static_cast<std::size_t>(block)] = true;
  }
  Eigen::MatrixXd before = Eigen::MatrixXd::Zero(3, n);
  before.leftCols(seen_.cols()) = seen_;
  const Eigen::MatrixXd move = now - before;
  const Eigen::MatrixXd cross = move * covariance_ * before.transpose();
  const Eigen::MatrixXd conditional =
      move * covariance_ * move.transpose() -
      cross * PseudoInverse(before * covariance_ * before.transpose()) * cross.transpose();
  const Eigen::Matrix3d at_robot = g * conditional * g.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(
      Eigen::Matrix3d(0.5 * (at_robot + at_robot.transpose())));
  const Eigen::Matrix3d q = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
                            eig.eigenvectors().transpose();

  // Those that left are marginalised out (their rows dropped).
  std::vector<Eigen::Index> kept;
  std::vector<int> ids;
  for (std::size_t a = 0; a < ids_.size(); ++a) {
    if (!in_map[a]) continue;
    kept.push_back(static_cast<Eigen::Index>(a));
    ids.push_back(ids_[a]);
  }
  const auto m = static_cast<Eigen::Index>(kept.size());
  Eigen::MatrixXd covariance(3 * m, 3 * m);
  seen_.setZero(3, 3 * m);
  for (Eigen::Index a = 0; a < m; ++a) {
    seen_.middleCols<3>(3 * a) = now.middleCols<3>(3 * kept[a]);
    for (Eigen::Index b = 0; b < m; ++b) {
      covariance.block<3, 3>(3 * a, 3 * b) = covariance_.block<3, 3>(3 * kept[a], 3 * kept[b]);
    }
  }
  covariance_ = std::move(covariance);
  ids_ = std::move(ids);
  return q;
}

void KeyframeErrors::Join(int id, const Eigen::Matrix3d& r, const Eigen::Vector2d& robot_xy) {
  const Eigen::Index k = 3 * size();
  const Eigen::Matrix3d g_inverse = LeverFromOrigin(-robot_xy);
  Eigen::MatrixXd seen = Eigen::MatrixXd::Zero(3, k);
  seen.leftCols(seen_.cols()) = seen_;
  const Eigen::MatrixXd cross = seen * covariance_;  // 3 x k
  covariance_.conservativeResize(k + 3, k + 3);
  covariance_.block(k, 0, 3, k) = cross;
  covariance_.block(0, k, k, 3) = cross.transpose();
  covariance_.block<3, 3>(k, k) = cross * seen.transpose() + g_inverse * r * g_inverse.transpose();
  ids_.push_back(id);
  seen_.conservativeResize(3, k + 3);
  seen_.leftCols(k) = seen;
  seen_.rightCols(3).setZero();
}

}  // namespace slamrig::slam
