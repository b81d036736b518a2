#include "slam/fusion/consistency.h"

#include <cstdio>

#include "slam/types/check.h"

namespace slamrig::slam {

std::string CovarianceCsv(const Trajectory& poses,
                          const std::vector<Eigen::Matrix3d>& covariances) {
  SLAMRIG_CHECK(poses.size() == covariances.size(), "CovarianceCsv: one covariance per pose");
  std::string out = "# time_s,xx,xy,xt,yy,yt,tt\n";
  char line[256];
  for (std::size_t i = 0; i < covariances.size(); ++i) {
    const Eigen::Matrix3d& p = covariances[i];
    std::snprintf(line, sizeof(line), "%.9f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                  poses[i].time.seconds(), p(0, 0), p(0, 1), p(0, 2), p(1, 1), p(1, 2), p(2, 2));
    out += line;
  }
  return out;
}

}  // namespace slamrig::slam
