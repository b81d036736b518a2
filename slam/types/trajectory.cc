#include "slam/types/trajectory.h"

#include <algorithm>
#include <cmath>

#include "slam/types/check.h"

namespace slamrig {

Trajectory::Trajectory(std::vector<StampedPose> poses) {
  poses_.reserve(poses.size());
  for (const StampedPose& p : poses) Append(p.time, p.pose);
}

void Trajectory::Append(Time time, const Pose2& pose) {
  if (!poses_.empty() && time < poses_.back().time) ++out_of_order_;
  poses_.push_back({time, pose});
}

std::optional<Pose2> Trajectory::Interpolate(Time time) const {
  if (poses_.empty() || !time_ordered() || time < poses_.front().time ||
      time > poses_.back().time) {
    return std::nullopt;
  }
  const auto after = std::lower_bound(poses_.begin(), poses_.end(), time,
                                      [](const StampedPose& p, Time t) { return p.time < t; });
  if (after->time == time || after == poses_.begin()) return after->pose;
  const auto before = after - 1;
  const double span = SecondsBetween(after->time, before->time);
  return InterpolatePoses(before->pose, after->pose, SecondsBetween(time, before->time) / span);
}

Pose2 InterpolatePoses(const Pose2& a, const Pose2& b, double s) {
  return Pose2(a.x() + s * (b.x() - a.x()), a.y() + s * (b.y() - a.y()),
               a.theta() + s * NormalizeAngle(b.theta() - a.theta()));
}

double Trajectory::PathLength() const {
  double length = 0.0;
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    length += (poses_[i].pose.translation() - poses_[i - 1].pose.translation()).norm();
  }
  return length;
}

}  // namespace slamrig
