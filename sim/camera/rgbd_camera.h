#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "sim/camera/floor_texture.h"
#include "sim/camera_spec.h"
#include "sim/world_spec.h"
#include "slam/types/pose2.h"
#include "slam/types/rgbd_frame.h"
#include "slam/types/time.h"

namespace slamrig::sim {

/// An RGB-D camera on the robot, rendered offscreen by MuJoCo through EGL (on the CPU with Mesa's
/// llvmpipe when there is no GPU). The world's static walls become boxes (cylinders, convex
/// meshes, thin boxes per polyline edge) `wall_height_m` tall, and the floor one plane with the
/// FloorTexture of the zones; each moving obstacle (box or circle) is a blue-grey prism as tall as
/// the walls on a mocap body of its own that Render() moves to where the simulator has it. The
/// camera rides a mocap body that Render() places at the robot's pose. Lighting is one ambient
/// headlight with no diffuse or specular part, and shadows, reflections and multisampling are off,
/// so a floor pixel shows its texel's colour unchanged.
///
/// Noise comes from the camera's own stream, RandomStream(seed, "camera"): enabling the camera
/// changes no other sensor's numbers. Not thread-safe; each camera owns an EGL context.
class RgbdCamera {
 public:
  /// Builds the MuJoCo model and the EGL context. Throws ConfigError for a spec that breaks a rule,
  /// ParseError for a missing texture file, std::runtime_error when EGL or MuJoCo fail.
  RgbdCamera(const WorldSpec& world, const CameraSpec& spec, std::uint64_t seed = 1);
  ~RgbdCamera();
  RgbdCamera(const RgbdCamera&) = delete;
  RgbdCamera& operator=(const RgbdCamera&) = delete;

  /// Renders the RGB and depth images seen with the robot at `map_from_base`, stamped `t`, the
  /// world's moving obstacles at `obstacle_positions_m` (map-frame origins, one per obstacle of
  /// the world; empty: where the last call put them, at first the starts of their paths). Throws
  /// ConfigError naming the camera and the pose when the camera sees nothing at all (outside the
  /// world, looking into the void): a blank image is a mistake, not data.
  RgbdFrame Render(const Pose2& map_from_base, Time t,
                   const std::vector<Eigen::Vector2d>& obstacle_positions_m = {});

  const CameraSpec& spec() const;
  /// The intrinsics actually rendered (principal point within 0.25 px of the spec's).
  const CameraIntrinsics& intrinsics() const;
  /// The floor texture drawn, for truth rasters.
  const FloorTexture& floor() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace slamrig::sim
