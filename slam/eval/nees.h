// Filter consistency tests (Bar-Shalom, Li and Kirubarajan, "Estimation with Applications to
// Tracking and Navigation", 2001, Sec. 5.4.2): the normalised estimation error squared
// e^T P^-1 e (Eq. 5.4.2-1) and the two-sided chi-square acceptance region of its average over N
// Monte Carlo runs (Eq. 5.4.2-6: N * ANEES is chi-square with N * n degrees of freedom).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// NEES of `estimate` with covariance `covariance` (x, y, yaw) against `truth`, both in the same
/// frame: e = truth - estimate with the angle wrapped. Infinity when the covariance is singular.
double PoseNees(const Pose2& truth, const Pose2& estimate, const Eigen::Matrix3d& covariance);

/// RotateCovariance lives with Pose2 (slam/types/pose2.h); callers here name it slam::.
using slamrig::RotateCovariance;

/// The acceptance region of the average NEES over `runs` runs of a `dimension`-dimensional state.
struct NeesBounds {
  double lower = 0.0;
  double upper = 0.0;
};

/// Two-sided 95 % bounds: chi2_{runs*dim}(0.025) / runs and chi2_{runs*dim}(0.975) / runs.
NeesBounds AneesBounds(int dimension, int runs);

/// The pose NEES of one run over time.
struct NeesSeries {
  std::vector<double> time_s;  ///< the scans' times, seconds
  std::vector<double> nees;
};

/// The NEES of every pose of `estimate` that has the reference at the same time: `covariances`
/// holds one matrix per pose of `estimate`, in a frame that the reference's frame turns by
/// `covariance_yaw_rad` (the estimator's own frame; the estimate itself is in the reference's).
/// Poses with a singular covariance (a first pose pinned at the origin) are left out, and so is
/// everything when the counts differ.
NeesSeries PoseNeesSeries(const Trajectory& estimate,
                          const std::vector<Eigen::Matrix3d>& covariances,
                          double covariance_yaw_rad, const Trajectory& reference);

}  // namespace slamrig::slam
