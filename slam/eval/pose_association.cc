// SE(2) alignment: Umeyama, "Least-squares estimation of transformation parameters between two
// point patterns", IEEE TPAMI 13(4), 1991, Eqs. 34-41 with c = 1, specialised to the plane.
#include "slam/eval/pose_association.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace slamrig::slam {

std::vector<PosePair> AssociatePoses(const Trajectory& estimate, const Trajectory& reference,
                                     const AssociationOptions& options) {
  std::vector<PosePair> pairs;
  bool same_stamps = estimate.size() == reference.size();
  for (std::size_t i = 0; same_stamps && i < estimate.size(); ++i) {
    same_stamps = estimate[i].time == reference[i].time;
  }
  if (same_stamps) {
    for (std::size_t i = 0; i < estimate.size(); ++i) {
      pairs.push_back({estimate[i].time, estimate[i].pose, reference[i].pose});
    }
    return pairs;
  }
  const std::vector<StampedPose>& ref = reference.poses();
  for (const StampedPose& e : estimate.poses()) {
    const auto after = std::lower_bound(ref.begin(), ref.end(), e.time,
                                        [](const StampedPose& p, Time t) { return p.time < t; });
    if (after == ref.end()) continue;
    if (after->time != e.time) {
      if (after == ref.begin()) continue;
      if (SecondsBetween(after->time, (after - 1)->time) > options.max_interpolation_gap_s)
        continue;
    }
    const std::optional<Pose2> r = reference.Interpolate(e.time);
    if (r) pairs.push_back({e.time, e.pose, *r});
  }
  return pairs;
}

Pose2 AlignSE2(const std::vector<PosePair>& pairs) {
  if (pairs.size() < 2) return Pose2();
  Eigen::Vector2d mean_e = Eigen::Vector2d::Zero(), mean_r = Eigen::Vector2d::Zero();
  for (const PosePair& p : pairs) {
    mean_e += p.estimate.translation();
    mean_r += p.reference.translation();
  }
  mean_e /= static_cast<double>(pairs.size());
  mean_r /= static_cast<double>(pairs.size());
  // Cross-covariance terms; the optimal rotation is atan2(sum cross, sum dot).
  double dot = 0.0, cross = 0.0;
  for (const PosePair& p : pairs) {
    const Eigen::Vector2d e = p.estimate.translation() - mean_e;
    const Eigen::Vector2d r = p.reference.translation() - mean_r;
    dot += e.dot(r);
    cross += e.x() * r.y() - e.y() * r.x();
  }
  const double theta = std::atan2(cross, dot);
  const Eigen::Vector2d t = mean_r - Eigen::Rotation2Dd(theta) * mean_e;
  return Pose2(t.x(), t.y(), theta);
}

}  // namespace slamrig::slam
