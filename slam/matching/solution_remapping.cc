// Degeneracy-aware solution remapping: Zhang, Kaess, Singh, "On Degeneracy of Optimization-based
// State Estimation Problems", ICRA 2016. The eigenvectors of the linearised problem's information
// J^T J whose eigenvalues fall below a threshold span the degenerate subspace; the solution's
// component there is replaced by the prior's (Sec. V, Eq. 11, with V_u the eigenvectors kept).
#include "slam/matching/solution_remapping.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace slamrig::slam {

int MatchConstraints::WeakCount(double min_ratio) const {
  const double largest = eigenvalues.y();
  int weak = 0;
  for (int i = 0; i < 2; ++i) weak += largest <= 0.0 || !(eigenvalues[i] >= min_ratio * largest);
  return weak;
}

MatchConstraints DecomposeInformation(const Eigen::Matrix3d& information) {
  MatchConstraints c;
  // What (x, y) are told once yaw takes whatever value suits it best.
  Eigen::Matrix2d translation = information.topLeftCorner<2, 2>();
  const double yaw = information(2, 2);
  if (yaw > 0.0) {
    const Eigen::Vector2d coupling = information.topRightCorner<2, 1>();
    translation -= coupling * coupling.transpose() / yaw;
  }
  if (!translation.allFinite()) return c;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(translation);
  c.eigenvalues = solver.eigenvalues();
  c.eigenvectors = solver.eigenvectors();
  return c;
}

Pose2 RemapAlongWeakDirections(const Pose2& predicted, const Pose2& matched,
                               const MatchConstraints& constraints, double min_ratio) {
  // The correction in the robot frame of `predicted`, where the constraints are.
  const double c = std::cos(predicted.theta()), s = std::sin(predicted.theta());
  const double dx = matched.x() - predicted.x(), dy = matched.y() - predicted.y();
  const Eigen::Vector2d delta(c * dx + s * dy, -s * dx + c * dy);
  const double largest = constraints.eigenvalues.y();
  Eigen::Vector2d kept = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i) {
    if (!(largest > 0.0) || !(constraints.eigenvalues[i] >= min_ratio * largest)) continue;
    const Eigen::Vector2d v = constraints.eigenvectors.col(i);
    kept += v * v.dot(delta);
  }
  return Pose2(predicted.x() + c * kept.x() - s * kept.y(),
               predicted.y() + s * kept.x() + c * kept.y(), matched.theta());
}

std::vector<Eigen::Vector2d> SurfaceNormals(std::span<const Eigen::Vector2d> points,
                                            double neighbour_m) {
  std::vector<Eigen::Vector2d> normals(points.size(), Eigen::Vector2d::Zero());
  const double max_sq = neighbour_m * neighbour_m;
  const std::size_t n = points.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = points[i];
    // A long chord keeps the range noise out of the normal.
    std::size_t first = i, last = i;
    while (first > 0 && (points[first - 1] - p).squaredNorm() <= max_sq) --first;
    while (last + 1 < n && (points[last + 1] - p).squaredNorm() <= max_sq) ++last;
    if (first == last) continue;
    const Eigen::Vector2d tangent = points[last] - points[first];
    const double length = tangent.norm();
    if (length > 0.0) normals[i] = Eigen::Vector2d(-tangent.y(), tangent.x()) / length;
  }
  return normals;
}

Eigen::Matrix3d ScanInformation(std::span<const Eigen::Vector2d> points,
                                std::span<const Eigen::Vector2d> normals) {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < points.size() && i < normals.size(); ++i) {
    const Eigen::Vector2d& p = points[i];
    const Eigen::Vector2d& normal = normals[i];
    if (normal.isZero()) continue;
    const Eigen::Vector3d j(normal.x(), normal.y(), p.x() * normal.y() - p.y() * normal.x());
    information += j * j.transpose();
  }
  return information;
}

MatchConstraints ScanGeometry(std::span<const Eigen::Vector2d> points) {
  constexpr double kNeighbourM = 0.3;
  if (points.empty()) return MatchConstraints{};
  return DecomposeInformation(ScanInformation(points, SurfaceNormals(points, kNeighbourM)));
}

SelectedPoints DropGrazingPoints(std::span<const Eigen::Vector2d> points,
                                 std::span<const Eigen::Vector2d> normals,
                                 double max_incidence_rad) {
  SelectedPoints out;
  const double min_cos = std::cos(max_incidence_rad);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d& p = points[i];
    const Eigen::Vector2d normal = i < normals.size() ? normals[i] : Eigen::Vector2d::Zero();
    const double range = p.norm();
    // The beam runs from the base origin (the lidar's offset is small beside a wall's distance).
    if (!normal.isZero() && range > 0.0 && std::abs(normal.dot(p)) < min_cos * range) continue;
    out.points.push_back(p);
    out.normals.push_back(normal);
  }
  return out;
}

}  // namespace slamrig::slam
