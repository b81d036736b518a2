// Circle fit to 2D points: the algebraic fit of Kasa ("A circle fitting procedure and its error
// analysis", IEEE Trans. Instrum. Meas., 1976, Eq. 3) as the start, refined by Gauss-Newton on the
// geometric distances |p - c| - r (Chernov, "Circular and Linear Regression", 2010, Sec. 4.2),
// which removes the algebraic fit's bias on short arcs (a pillar seen from one side).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace slamrig::slam {

/// A fitted circle.
struct CircleFit {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  double rms_m = 0.0;  ///< root mean square of the points' geometric distances to the circle
  /// Covariance of the centre (m^2) from the Gauss-Newton normal equations and the residuals.
  Eigen::Matrix2d center_covariance = Eigen::Matrix2d::Zero();
  double radius_variance = 0.0;  ///< of the radius (m^2), from the same normal equations
};

/// The circle through `points` (at least 3, not collinear), or nullopt when there is none.
std::optional<CircleFit> FitCircle(const std::vector<Eigen::Vector2d>& points);

}  // namespace slamrig::slam
