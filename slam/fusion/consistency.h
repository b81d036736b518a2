// Filter consistency tests (Bar-Shalom, Li and Kirubarajan, "Estimation with Applications to
// Tracking and Navigation", 2001, Sec. 5.4.2): the normalised estimation error squared
// e^T P^-1 e (Eq. 5.4.2-1) and the two-sided chi-square acceptance region of its average over N
// Monte Carlo runs (Eq. 5.4.2-6: N * ANEES is chi-square with N * n degrees of freedom).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// NEES of `estimate` with covariance `covariance` (x, y, yaw) against `truth`, both in the same
/// frame: e = truth - estimate with the angle wrapped. Infinity when the covariance is singular.
double PoseNees(const Pose2& truth, const Pose2& estimate, const Eigen::Matrix3d& covariance);

/// RotateCovariance lives with Pose2 (slam/types/pose2.h); callers here name it slam::.
using slamrig::RotateCovariance;

/// CSV of one covariance per pose, "# time_s,xx,xy,xt,yy,yt,tt" then one line per pose (m^2,
/// m rad, rad^2); `covariances` has one matrix per pose of `poses` (checked).
std::string CovarianceCsv(const Trajectory& poses, const std::vector<Eigen::Matrix3d>& covariances);

/// The `p` quantile of the chi-square distribution with `dof` degrees of freedom
/// (Wilson-Hilferty's start refined by Newton steps on the incomplete gamma function).
double ChiSquareQuantile(double p, double dof);

/// The `p` quantile (p >= 0.5) of the F distribution with (d1, d2) degrees of freedom, by
/// Paulson's cube-root normal approximation (Abramowitz and Stegun 26.6.15; within ~2 % of the
/// tables for d2 >= 3, cruder below).
double FQuantile(double p, double d1, double d2);

/// The acceptance region of the average NEES over `runs` runs of a `dimension`-dimensional state.
struct NeesBounds {
  double lower = 0.0;
  double upper = 0.0;
};

/// Two-sided 95 % bounds: chi2_{runs*dim}(0.025) / runs and chi2_{runs*dim}(0.975) / runs.
NeesBounds AneesBounds(int dimension, int runs);

}  // namespace slamrig::slam
