#pragma once

#include <Eigen/Core>
#include <cmath>
#include <numbers>

namespace slamrig {

/// Wraps an angle into (-pi, pi].
inline double NormalizeAngle(double angle_rad) {
  double a = std::remainder(angle_rad, 2.0 * std::numbers::pi);  // in [-pi, pi]
  if (a <= -std::numbers::pi) a += 2.0 * std::numbers::pi;
  return a;
}

/// The matrix that rotates a vector by `yaw_rad`: [cos -sin; sin cos].
inline Eigen::Matrix2d RotationMatrix(double yaw_rad) {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

/// A covariance of (x, y, yaw) expressed in a frame rotated by `yaw_rad`: J P J^T with
/// J = diag(R(yaw_rad), 1). The yaw variance is unchanged.
inline Eigen::Matrix3d RotateCovariance(const Eigen::Matrix3d& covariance, double yaw_rad) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j.topLeftCorner<2, 2>() = RotationMatrix(yaw_rad);
  return j * covariance * j.transpose();
}

/// A rigid transform in SE(2): rotation by `theta` then translation by (x, y).
/// Read `a_from_b` as the pose of frame b expressed in frame a, so that
/// `world_from_robot * robot_from_laser == world_from_laser`. `theta` is always in (-pi, pi].
class Pose2 {
 public:
  constexpr Pose2() = default;
  Pose2(double x_m, double y_m, double theta_rad)
      : x_(x_m), y_(y_m), theta_(NormalizeAngle(theta_rad)) {}

  double x() const { return x_; }
  double y() const { return y_; }
  double theta() const { return theta_; }
  Eigen::Vector2d translation() const { return {x_, y_}; }
  /// The rotation part as a matrix: R(theta), so that (*this) * p == R p + translation().
  Eigen::Matrix2d Rotation() const { return RotationMatrix(theta_); }

  /// Composition: (*this) followed by `other`, i.e. a_from_c = a_from_b * b_from_c.
  Pose2 operator*(const Pose2& other) const {
    const double c = std::cos(theta_), s = std::sin(theta_);
    return Pose2(x_ + c * other.x_ - s * other.y_, y_ + s * other.x_ + c * other.y_,
                 theta_ + other.theta_);
  }

  /// Maps a point from the child frame into this pose's parent frame.
  Eigen::Vector2d operator*(const Eigen::Vector2d& point) const {
    const double c = std::cos(theta_), s = std::sin(theta_);
    return {x_ + c * point.x() - s * point.y(), y_ + s * point.x() + c * point.y()};
  }

  /// The inverse transform: b_from_a for a_from_b.
  Pose2 Inverse() const {
    const double c = std::cos(theta_), s = std::sin(theta_);
    return Pose2(-c * x_ - s * y_, s * x_ - c * y_, -theta_);
  }

  /// Relative pose `this^-1 * other`: where `other` is, seen from this pose.
  Pose2 Between(const Pose2& other) const { return Inverse() * other; }

  friend bool operator==(const Pose2&, const Pose2&) = default;

 private:
  double x_ = 0.0;
  double y_ = 0.0;
  double theta_ = 0.0;
};

/// sin(x) / x, with its Taylor series near 0.
inline double Sinc(double x) {
  if (std::abs(x) < 1e-4) return 1.0 - x * x / 6.0;
  return std::sin(x) / x;
}

/// The pose reached by driving `distance_m` along a circular arc that turns the heading by
/// `turn_rad` (a constant forward speed and yaw rate), in the frame of its start: the chord
/// distance * sinc(turn / 2) at half the turn.
inline Pose2 ArcIncrement(double distance_m, double turn_rad) {
  const double half = 0.5 * turn_rad;
  const double chord = distance_m * Sinc(half);
  return Pose2(chord * std::cos(half), chord * std::sin(half), turn_rad);
}

}  // namespace slamrig
