#pragma once

#include <optional>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/time.h"

namespace slamrig {

/// One stamped pose of base_link in some fixed frame.
struct StampedPose {
  Time time;
  Pose2 pose;
};

/// A time-ordered sequence of stamped poses (an estimate or a reference).
/// Times are non-decreasing; `Append` enforces it.
class Trajectory {
 public:
  Trajectory() = default;
  explicit Trajectory(std::vector<StampedPose> poses);

  /// Adds a pose; its time must not be earlier than the last one (checked).
  void Append(Time time, const Pose2& pose);

  const std::vector<StampedPose>& poses() const { return poses_; }
  std::size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }
  const StampedPose& operator[](std::size_t i) const { return poses_[i]; }

  /// The pose at `time`, linearly interpolated (angle along the shortest arc) between the two
  /// neighbouring samples; nullopt outside [front, back] time.
  std::optional<Pose2> Interpolate(Time time) const;

  /// Sum of the distances between consecutive positions, metres.
  double PathLength() const;

 private:
  std::vector<StampedPose> poses_;
};

}  // namespace slamrig
