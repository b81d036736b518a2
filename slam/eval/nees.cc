#include "slam/eval/nees.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "slam/eval/chi_square.h"
#include "slam/eval/pose_association.h"
#include "slam/types/check.h"

namespace slamrig::slam {

double PoseNees(const Pose2& truth, const Pose2& estimate, const Eigen::Matrix3d& covariance) {
  const Eigen::Vector3d e(truth.x() - estimate.x(), truth.y() - estimate.y(),
                          NormalizeAngle(truth.theta() - estimate.theta()));
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(covariance);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) {
    return std::numeric_limits<double>::infinity();
  }
  return e.dot(ldlt.solve(e));
}

NeesBounds AneesBounds(int dimension, int runs) {
  SLAMRIG_CHECK(dimension > 0 && runs > 0, "AneesBounds: dimension and runs > 0");
  const double dof = static_cast<double>(dimension) * runs;
  return {ChiSquareQuantile(0.025, dof) / runs, ChiSquareQuantile(0.975, dof) / runs};
}

NeesSeries PoseNeesSeries(const Trajectory& estimate,
                          const std::vector<Eigen::Matrix3d>& covariances,
                          double covariance_yaw_rad, const Trajectory& reference) {
  NeesSeries series;
  if (covariances.size() != estimate.size()) return series;
  std::size_t i = 0;
  for (const PosePair& p : AssociatePoses(estimate, reference)) {
    while (i < estimate.size() && estimate[i].time < p.time) ++i;
    if (i == estimate.size() || estimate[i].time != p.time) continue;
    const double nees =
        PoseNees(p.reference, p.estimate, RotateCovariance(covariances[i], covariance_yaw_rad));
    if (!std::isfinite(nees)) continue;
    series.time_s.push_back(p.time.seconds());
    series.nees.push_back(nees);
  }
  return series;
}

}  // namespace slamrig::slam
