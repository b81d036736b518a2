#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/types/rgbd_frame.h"

namespace slamrig::sim {

/// How the depth image is corrupted.
enum class DepthModel {
  kIdeal,            ///< the rendered z-depth, unchanged
  kKinectDisparity,  ///< through the Kinect's disparity: quantized, with noise in disparity units
};

/// The texture of one floor zone (matched by the zone's name in the world file).
struct ZoneTexture {
  std::string zone;     ///< textures every zone whose name contains this ("carpet")
  std::string image;    ///< PNG; relative to CameraSpec::texture_dir
  double tile_m = 1.0;  ///< side of the floor square one copy of the image covers
};

/// An RGB-D camera on the robot (the robot file's `camera:` block), rendered by MuJoCo in
/// sim/camera; the options live here so that a RobotSpec can carry them. Defaults: the ECE276A
/// robot's Kinect at 640 x 480 and 10 Hz with the intrinsics and mounting of the reports (Zafari,
/// ECE276A report, "Texture Mapping"; the course's robot configuration).
struct CameraSpec {
  std::string name = "kinect";  ///< names the camera in errors
  int width_px = 640;           ///< image columns
  int height_px = 480;          ///< image rows
  double rate_hz = 10.0;        ///< frames per second the caller should render
  /// fx must equal fy: MuJoCo 2.2 renders square pixels only (one fovy, no separate fovx). The
  /// reports give the principal point as (242.94, 315.84) in (row, column) order for their 640 x
  /// 480 images, hence cx = 315.84, cy = 242.94. MuJoCo puts the principal point at the image
  /// centre: the camera renders a larger image and crops it, which places the principal point to
  /// within 0.25 px; RgbdFrame::intrinsics holds the values actually rendered.
  CameraIntrinsics intrinsics;
  CameraMount mount;  ///< base_from_camera of the RGB camera
  /// Depth camera origin along the RGB camera's optical x axis (right): Kinect v1's IR camera sits
  /// about 2.5 cm beside its colour camera. 0 renders one view for both images (half the cost).
  double depth_offset_x_m = 0.025;

  DepthModel depth_model = DepthModel::kKinectDisparity;  ///< how depth is corrupted
  double disparity_noise_stddev = 0.5;  ///< Gaussian noise in raw disparity units (kKinect...)
  bool quantize_disparity = true;       ///< round the noisy disparity to an integer (kKinect...)
  double min_depth_m = 0.5;             ///< nearer readings become 0 (no reading)
  double max_depth_m = 5.0;             ///< farther readings become 0
  double rgb_noise_stddev = 0.0;        ///< Gaussian noise per colour byte, 0 = none

  std::string texture_dir;                ///< where image files are; empty: worlds/textures
  std::string floor_image = "tiles.png";  ///< floor outside every textured zone
  double floor_tile_m = 1.0;              ///< side of the square one floor image covers
  /// Zone textures, later entries winning; zones no entry names show the floor image, and entries
  /// naming no zone of the world are unused.
  std::vector<ZoneTexture> zones = {{"carpet", "carpet.png", 1.0}, {"ice", "concrete.png", 2.0}};
  double floor_texel_m = 0.01;  ///< texel of the floor texture the zones are composed into
  double wall_height_m = 2.0;   ///< walls are extruded to this height
  Eigen::Vector3d wall_rgb = Eigen::Vector3d(0.85, 0.85, 0.8);  ///< wall colour, 0..1 (x image)
  std::string wall_image = "concrete.png";  ///< wall texture; empty: plain wall_rgb
  double wall_tile_m = 1.0;                 ///< side of the square one wall image covers
  double znear_m = 0.05;                    ///< near clipping plane
  double zfar_m = 50.0;                     ///< far clipping plane

  /// The time between frames.
  double period_s() const { return 1.0 / rate_hz; }

  /// One message per broken rule ("camera.width_px = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

}  // namespace slamrig::sim
