#include "slam/fusion/circle_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

namespace slamrig::slam {

std::optional<CircleFit> FitCircle(const std::vector<Eigen::Vector2d>& points) {
  const int n = static_cast<int>(points.size());
  if (n < 3) return std::nullopt;
  // Kasa: x^2 + y^2 + D x + E y + F = 0 in least squares, around the centroid for conditioning.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) mean += p;
  mean /= n;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d q = p - mean;
    const Eigen::Vector3d a(q.x(), q.y(), 1.0);
    ata += a * a.transpose();
    atb -= a * q.squaredNorm();
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (lu.rank() < 3) return std::nullopt;
  const Eigen::Vector3d def = lu.solve(atb);
  Eigen::Vector2d c(-0.5 * def(0), -0.5 * def(1));
  const double r2 = c.squaredNorm() - def(2);
  if (!(r2 > 0.0)) return std::nullopt;
  double r = std::sqrt(r2);

  // Gauss-Newton on the geometric residuals |q - c| - r over (cx, cy, r).
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  double sum_sq = 0.0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    jtj.setZero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    sum_sq = 0.0;
    for (const Eigen::Vector2d& p : points) {
      const Eigen::Vector2d d = p - mean - c;
      const double dist = d.norm();
      if (dist < 1e-12) continue;
      const Eigen::Vector3d j(-d.x() / dist, -d.y() / dist, -1.0);
      const double residual = dist - r;
      jtj += j * j.transpose();
      jtr += j * residual;
      sum_sq += residual * residual;
    }
    const Eigen::Vector3d step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) return std::nullopt;
    c += step.head<2>();
    r += step(2);
    if (step.norm() < 1e-12) break;
  }
  if (!(r > 0.0) || !c.allFinite()) return std::nullopt;
  CircleFit fit;
  fit.center = c + mean;
  fit.radius_m = r;
  fit.rms_m = std::sqrt(sum_sq / n);
  const double sigma2 = n > 3 ? sum_sq / (n - 3) : 0.0;
  const Eigen::Matrix3d covariance = sigma2 * jtj.inverse();
  fit.center_covariance = covariance.topLeftCorner<2, 2>();
  fit.radius_variance = covariance(2, 2);
  return fit;
}

}  // namespace slamrig::slam
