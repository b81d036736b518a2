#include "scenarios/texture_run.h"

#include <utility>

#include "slam/eval/pose_association.h"
#include "slam/eval/trajectory_error.h"

namespace slamrig::scenario {

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

}  // namespace slamrig::scenario
