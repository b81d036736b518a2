#pragma once

#include <cstdint>
#include <deque>
#include <optional>

#include "sim/camera/rgbd_camera.h"
#include "sim/simulator.h"

namespace slamrig::sim {

/// The simulator's record stream with the robot's RGB-D camera in it: each StepResult of the
/// simulator, with the frames rendered since merged in time order (a frame after the records
/// stamped at or before its time). Frame k (k >= 1) is rendered at the first physics step at or
/// after k / rate_hz, at the true pose of that step, and stamped with its time; its truth is the
/// simulator's truth then. The simulator only ever sees Step() and Flush() calls through here;
/// its other controls (Teleport, overrides) stay the caller's. The camera's noise has its own
/// stream, so a run with the camera gives every other record bit for bit as one without.
/// Moving obstacles are rendered where the simulator has them at each frame. A camera without a
/// single depth reading in its first frame, or in every frame for kMaxBlindS seconds, is a
/// ConfigError naming its min_depth_m, max_depth_m and mount: such a camera maps nothing.
class CameraRig {
 public:
  /// Seconds of frames without any depth reading after which the camera is judged blind.
  static constexpr double kMaxBlindS = 5.0;

  /// Renders the camera `spec` in `simulator`'s world (which must outlive the rig). Throws as
  /// RgbdCamera does.
  CameraRig(Simulator* simulator, const CameraSpec& spec, std::uint64_t seed);

  /// Advances the simulator one step; its records and the frames due, in time order.
  StepResult Step();
  /// The simulator's held records and the frames still waiting for them.
  StepResult Flush();

  /// The camera (its spec, intrinsics and floor texture).
  const RgbdCamera& camera() const { return camera_; }
  /// Frames rendered so far.
  int frames() const { return frames_; }

 private:
  struct Pending {
    RgbdFrame frame;
    TruthSample truth;
  };
  StepResult Merge(StepResult step, Time released_before);
  void CheckDepth(const RgbdFrame& frame, const Pose2& map_from_base);

  Simulator& simulator_;
  RgbdCamera camera_;
  std::int64_t period_ns_ = 0;
  std::int64_t next_frame_ = 1;
  std::deque<Pending> pending_;  // rendered, waiting for the records stamped before them
  int frames_ = 0;
  std::optional<Time> blind_since_;  // first of the latest run of frames without depth
};

}  // namespace slamrig::sim
