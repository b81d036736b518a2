#include "scenarios/texture_run.h"

#include <Eigen/Core>
#include <cmath>
#include <utility>

#include "slam/eval/pose_association.h"
#include "slam/eval/trajectory_error.h"

namespace slamrig::scenario {

PoseErrorParts SplitPoseError(const Trajectory& estimate, const Trajectory& truth,
                              double half_window_s) {
  std::vector<StampedPose> reference;
  std::vector<Eigen::Vector3d> error;
  for (const StampedPose& t : truth.poses()) {
    const std::optional<Pose2> e = estimate.Interpolate(t.time);
    if (!e) continue;
    reference.push_back(t);
    error.emplace_back(e->x() - t.pose.x(), e->y() - t.pose.y(),
                       std::remainder(e->theta() - t.pose.theta(), 2.0 * M_PI));
  }
  // The centred moving average by prefix sums over the stamps within the window.
  const std::size_t n = error.size();
  std::vector<Eigen::Vector3d> prefix(n + 1, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + error[i];
  PoseErrorParts parts;
  std::size_t lo = 0, hi = 0;  // the window is [lo, hi)
  for (std::size_t i = 0; i < n; ++i) {
    while (SecondsBetween(reference[i].time, reference[lo].time) > half_window_s) ++lo;
    while (hi < n && SecondsBetween(reference[hi].time, reference[i].time) <= half_window_s) ++hi;
    const Eigen::Vector3d slow = (prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo);
    const Eigen::Vector3d jitter = error[i] - slow;
    const Pose2& t = reference[i].pose;
    parts.slow.Append(reference[i].time,
                      Pose2(t.x() + slow.x(), t.y() + slow.y(), t.theta() + slow.z()));
    parts.jitter.Append(reference[i].time,
                        Pose2(t.x() + jitter.x(), t.y() + jitter.y(), t.theta() + jitter.z()));
  }
  return parts;
}

TextureRun::TextureRun(const slam::TextureMapOptions& options, cv::Mat3b truth,
                       cv::Mat1b truth_floor)
    : options_(options), truth_(std::move(truth)), truth_floor_(std::move(truth_floor)) {}

void TextureRun::Add(const RgbdFrame& frame, const Pose2& map_from_base) {
  slam::FloorPixels pixels = slam::ExtractFloorPixels(frame, options_);
  floor_pixels_ += static_cast<long long>(pixels.base_xy_m.size());
  depth_readings_ += pixels.depth_readings;
  pixels_.push_back(std::move(pixels));
  true_poses_.push_back(map_from_base);
}

TextureResult TextureRun::Score(const slam::TextureMap& map, int frames) const {
  TextureResult r;
  r.colors = map.Colors();
  r.observed = map.Observed();
  r.score = slam::ScoreTexture(r.colors, r.observed, truth_, truth_floor_);
  r.frames = frames;
  return r;
}

TextureResult TextureRun::WithTruePoses() const {
  slam::TextureMap map(options_);
  for (std::size_t i = 0; i < pixels_.size(); ++i) map.Insert(pixels_[i], true_poses_[i]);
  return Score(map, frames());
}

TextureResult TextureRun::WithPoses(const Trajectory& map_from_base) const {
  slam::TextureMap map(options_);
  int frames = 0;
  for (const slam::FloorPixels& p : pixels_) {
    const std::optional<Pose2> pose = map_from_base.Interpolate(p.time);
    if (!pose) continue;
    map.Insert(p, *pose);
    ++frames;
  }
  return Score(map, frames);
}

TextureResult TextureRun::WithAlignedPoses(const Trajectory& map_from_base,
                                           const Trajectory& truth) const {
  if (slam::AssociatePoses(map_from_base, truth).size() < 2) return WithPoses(map_from_base);
  const Pose2 reference_from_estimate =
      slam::ComputeAte(map_from_base, truth).reference_from_estimate;
  Trajectory aligned;
  for (const StampedPose& p : map_from_base.poses()) {
    aligned.Append(p.time, reference_from_estimate * p.pose);
  }
  TextureResult r = WithPoses(aligned);
  r.reference_from_estimate = reference_from_estimate;
  return r;
}

std::pair<TextureResult, TextureResult> TextureRun::WithErrorParts(const Trajectory& map_from_base,
                                                                   const Trajectory& truth,
                                                                   double half_window_s) const {
  Trajectory aligned;
  if (slam::AssociatePoses(map_from_base, truth).size() >= 2) {
    const Pose2 reference_from_estimate =
        slam::ComputeAte(map_from_base, truth).reference_from_estimate;
    for (const StampedPose& p : map_from_base.poses()) {
      aligned.Append(p.time, reference_from_estimate * p.pose);
    }
  } else {
    aligned = map_from_base;
  }
  const PoseErrorParts parts = SplitPoseError(aligned, truth, half_window_s);
  return {WithPoses(parts.slow), WithPoses(parts.jitter)};
}

}  // namespace slamrig::scenario
