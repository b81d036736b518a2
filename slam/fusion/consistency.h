// The covariance CSV written beside trajectories. The consistency statistics themselves (NEES,
// ANEES bounds, chi-square and F quantiles) live in slam/eval/nees.h and slam/eval/chi_square.h,
// included here for the code that still reaches them through this header.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/eval/chi_square.h"
#include "slam/eval/nees.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// CSV of one covariance per pose, "# time_s,xx,xy,xt,yy,yt,tt" then one line per pose (m^2,
/// m rad, rad^2); `covariances` has one matrix per pose of `poses` (checked).
std::string CovarianceCsv(const Trajectory& poses, const std::vector<Eigen::Matrix3d>& covariances);

}  // namespace slamrig::slam
