#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "slam/types/time.h"

namespace slamrig {

/// Pinhole intrinsics in pixels, principal point in pixel-centre coordinates: the centre of the
/// top-left pixel is (0, 0), u grows to the right and v downwards.
struct CameraIntrinsics {
  double fx_px = 585.05108211;  ///< focal length along u (the ECE276A Kinect, Zafari's report)
  double fy_px = 585.05108211;  ///< focal length along v
  double cx_px = 315.83800193;  ///< principal point, column
  double cy_px = 242.94140713;  ///< principal point, row
};

/// Where a camera sits on the robot: base_from_camera as x, y, z and roll, pitch, yaw (applied
/// as Rz(yaw) Ry(pitch) Rx(roll)). The camera frame follows REP-103 like base_link (x along the
/// optical axis, y left, z up), so a positive pitch tilts the camera down; pixels live in the
/// optical frame (x right, y down, z forward) that OpticalFromCamera() relates to it.
struct CameraMount {
  double x_m = 0.18;        ///< forward of base_link (ECE276A robot's Kinect)
  double y_m = 0.005;       ///< left of base_link
  double z_m = 0.36;        ///< above the floor
  double roll_rad = 0.0;    ///< about the optical axis
  double pitch_rad = 0.36;  ///< downwards tilt
  double yaw_rad = 0.021;   ///< CCW about z

  /// base_from_camera as a rigid transform.
  Eigen::Isometry3d BaseFromCamera() const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(x_m, y_m, z_m);
    t.linear() = (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    return t;
  }
};

/// camera_from_optical: the optical frame's x (right), y (down), z (forward) in the camera frame.
inline Eigen::Matrix3d CameraFromOptical() {
  Eigen::Matrix3d r;
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return r;
}

/// One RGB-D image pair. The depth image was taken by a depth camera displaced from the RGB camera
/// by `depth_offset_x_m` along the optical x axis (a Kinect's IR camera sits beside its colour
/// camera); both share `intrinsics` and the image size. Pixel (u, v) of either image is element
/// v * width + u; the RGB bytes are interleaved r, g, b.
struct RgbdFrame {
  Time time;                      ///< when both images were taken
  int width = 0;                  ///< columns
  int height = 0;                 ///< rows
  std::vector<std::uint8_t> rgb;  ///< width * height * 3 bytes, top row first
  std::vector<float> depth_m;     ///< width * height z-depths in metres; 0 = no reading
  CameraIntrinsics intrinsics;    ///< of both images
  CameraMount base_from_camera;   ///< the RGB camera on the robot
  double depth_offset_x_m = 0.0;  ///< depth camera origin in the RGB optical frame, along x

  /// base_from_optical of the RGB camera.
  Eigen::Isometry3d BaseFromRgbOptical() const {
    Eigen::Isometry3d t = base_from_camera.BaseFromCamera();
    t.linear() = t.linear() * CameraFromOptical();
    return t;
  }
  /// base_from_optical of the depth camera.
  Eigen::Isometry3d BaseFromDepthOptical() const {
    return BaseFromRgbOptical() * Eigen::Translation3d(depth_offset_x_m, 0.0, 0.0);
  }
};

}  // namespace slamrig
