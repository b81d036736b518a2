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
  friend bool operator==(const StampedPose&, const StampedPose&) = default;
};

/// The pose a fraction `s` of the way from `a` to `b`: linear in x and y, the angle along the
/// shorter arc (s = 0 gives a, s = 1 gives b's position and an angle equal to b's modulo 2 pi).
Pose2 InterpolatePoses(const Pose2& a, const Pose2& b, double s);

/// A sequence of stamped poses (an estimate or a reference), in the order they were produced
/// (one per scan, say). Stamps are normally non-decreasing; a real log's stamps may go backwards
/// in places, and then each pose still keeps its own stamp (`time_ordered()` is false) rather than
/// a made-up one, so outside tools pair it with the right reference pose.
class Trajectory {
 public:
  Trajectory() = default;
  explicit Trajectory(std::vector<StampedPose> poses);

  /// Adds a pose at the end, whatever its stamp.
  void Append(Time time, const Pose2& pose);
  /// True when no stamp is earlier than the one before it.
  bool time_ordered() const { return out_of_order_ == 0; }
  /// Number of poses stamped earlier than their predecessor.
  int out_of_order() const { return out_of_order_; }

  const std::vector<StampedPose>& poses() const { return poses_; }
  std::size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }
  const StampedPose& operator[](std::size_t i) const { return poses_[i]; }

  /// The pose at `time`, linearly interpolated (angle along the shortest arc) between the two
  /// neighbouring samples; nullopt outside [front, back] time, and on a trajectory whose stamps
  /// are not time-ordered (there is no "the pose at a time" there).
  std::optional<Pose2> Interpolate(Time time) const;

  /// Sum of the distances between consecutive positions, metres.
  double PathLength() const;

 private:
  std::vector<StampedPose> poses_;
  int out_of_order_ = 0;
};

}  // namespace slamrig
