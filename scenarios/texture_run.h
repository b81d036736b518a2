#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/texture/texture_map.h"
#include "slam/texture/texture_score.h"
#include "slam/types/pose2.h"
#include "slam/types/rgbd_frame.h"
#include "slam/types/trajectory.h"

namespace slamrig::scenario {

/// A texture map built from a run's frames with one set of poses, and its score.
struct TextureResult {
  cv::Mat3b colors;    ///< mean colour per cell (r, g, b), black where unseen
  cv::Mat1b observed;  ///< 255 where a cell was seen
  slam::TextureScore score;
  int frames = 0;  ///< frames mapped (those with a pose at their time)
  /// The rigid motion applied to the poses before mapping (identity unless aligned).
  Pose2 reference_from_estimate;
};

/// A trajectory's error against the truth split in two, each part added alone to the true poses
/// (at the truth's stamps): `slow` carries the centred moving average of the error, the part that
/// distorts a map built from the poses; `jitter` the rest, the scan-to-scan noise.
struct PoseErrorParts {
  Trajectory slow;
  Trajectory jitter;
};

/// Splits the error of `estimate` (interpolated at each stamp of `truth`; stamps outside its span
/// are left out) as (dx, dy) in the map frame and the wrapped heading difference, averaged over
/// the stamps within `half_window_s` either side. Same frame for both: align `estimate` first.
PoseErrorParts SplitPoseError(const Trajectory& estimate, const Trajectory& truth,
                              double half_window_s);

/// The texture side of a scenario run with a camera. Each frame is reduced once to its floor
/// pixels in base_link (slam::ExtractFloorPixels, independent of the pose), kept with the true
/// pose at its time; afterwards any trajectory (an estimator's final poses, the truth) maps them,
/// interpolated at the frame stamps, and is scored against the world's true floor texture. No
/// estimator knows about it: texture mapping follows whatever poses it is given.
class TextureRun {
 public:
  /// `options` lays out the raster (extents, resolution, floor threshold, pixel stride); `truth`
  /// and `truth_floor` are the true floor texture and floor mask on that raster.
  TextureRun(const slam::TextureMapOptions& options, cv::Mat3b truth, cv::Mat1b truth_floor);

  /// A frame, taken at the true pose `map_from_base`.
  void Add(const RgbdFrame& frame, const Pose2& map_from_base);

  /// The map from the true poses at the frames.
  TextureResult WithTruePoses() const;
  /// The map from `map_from_base` (map frame) interpolated at each frame's time; frames outside
  /// its time span are left out.
  TextureResult WithPoses(const Trajectory& map_from_base) const;
  /// The map from `map_from_base` moved by the SE(2) alignment ATE applies to it against
  /// `truth` (the true poses at the scans; slam::ComputeAte), so the texture is scored in the
  /// frame the trajectory is. A SLAM map's frame is defined up to a rigid motion, and on a
  /// checkered floor a rigid shift of the whole map by 2 cm costs about 3 dB that says nothing
  /// about the map's shape (sim/camera/office_texture_test.cc). With fewer than two pose pairs
  /// there is no alignment and the poses are used as they are.
  TextureResult WithAlignedPoses(const Trajectory& map_from_base, const Trajectory& truth) const;

  /// SplitPoseError of `map_from_base` after WithAlignedPoses' alignment: the maps from the true
  /// poses plus each part alone, in that order, which say where the texture loss comes from.
  std::pair<TextureResult, TextureResult> WithErrorParts(const Trajectory& map_from_base,
                                                         const Trajectory& truth,
                                                         double half_window_s) const;

  const slam::TextureMapOptions& options() const { return options_; }
  /// The true floor texture, r, g, b.
  const cv::Mat3b& truth() const { return truth_; }
  int frames() const { return static_cast<int>(pixels_.size()); }
  /// Floor pixels over every frame (0: the camera never saw the floor).
  long long floor_pixels() const { return floor_pixels_; }
  /// Depth readings in range over every frame (0: the camera never measured anything).
  long long depth_readings() const { return depth_readings_; }

 private:
  TextureResult Score(const slam::TextureMap& map, int frames) const;

  slam::TextureMapOptions options_;
  cv::Mat3b truth_;
  cv::Mat1b truth_floor_;
  std::vector<slam::FloorPixels> pixels_;
  std::vector<Pose2> true_poses_;
  long long floor_pixels_ = 0;
  long long depth_readings_ = 0;
};

}  // namespace slamrig::scenario
