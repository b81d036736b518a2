#pragma once

#include <string>
#include <vector>

#include "slam/io/dataset.h"
#include "slam/types/pose2.h"
#include "slam/types/rgbd_frame.h"

namespace slamrig::slam {

/// The files of one ECE276A robot dataset (UCSD ECE276A project 2: encoders, IMU, Hokuyo,
/// Kinect).
struct Ece276aFiles {
  std::string encoders;  ///< Encoders<N>.npz or encoders<N>.csv.gz (required)
  std::string imu;       ///< Imu<N>.npz or imu<N>.csv.gz (empty: none)
  std::string hokuyo;    ///< Hokuyo<N>.npz (empty: none; the shared copy has no lidar)
  std::string kinect;    ///< Kinect<N>.npz, the images' time stamps (empty: no camera frames)
  /// Images of frame k (from 1): `kinect_images`/RGB<N>/rgb<N>_<k>.png and
  /// `kinect_images`/Disparity<N>/disparity<N>_<k>.png; the dataRGBD folder beside Kinect<N>.npz.
  std::string kinect_images;
  int dataset = 0;  ///< the <N> of the file names
};

/// How ECE276A logs are turned into records.
struct Ece276aReadOptions {
  /// The Hokuyo's mounting pose on base_link: 0.13323 m ahead of the rear axle's centre
  /// (RobotConfiguration.pdf: 298.33 mm lidar position minus half the 330.20 mm wheel base).
  Pose2 base_from_lidar{0.13323, 0.0, 0.0};
  double gravity_m_s2 = 9.80665;  ///< the IMU's accelerations are in g

  /// The Kinect's colour camera: the reports' intrinsics (Zafari: f = 585.05 px, principal point
  /// (242.94, 315.84) in (row, column) order) and its mounting on the ECE276A robot.
  CameraIntrinsics camera_intrinsics;
  CameraMount base_from_camera;  ///< (0.18, 0.005, 0.36) m, pitch 0.36 rad, yaw 0.021 rad
  /// The depth (IR) camera beside the colour camera along the optical x axis; the reports
  /// describe the offset without a figure, and Kinect v1's baseline is about 2.5 cm (the value
  /// the simulated camera renders with by default).
  double depth_offset_x_m = 0.025;
  /// Reads every k-th disparity image only: a 640 x 480 frame is 2.1 MB in memory, and the
  /// course's datasets hold about 2,400 each.
  int kinect_every = 1;
};

/// Finds the files of a dataset from `path`: a dataset folder plus number ("DIR/20"), or any one
/// of its files ("DIR/Encoders20.npz", "DIR/imu21.csv.gz", "DIR/Hokuyo23.npz",
/// "DIR/Kinect20.npz"). npz files win over csv.gz; the Kinect images are looked for in
/// DIR/dataRGBD. Throws ParseError when no encoder file is found.
Ece276aFiles FindEce276aFiles(const std::string& path);

/// True if `path` names an ECE276A dataset as FindEce276aFiles understands it.
bool LooksLikeEce276a(const std::string& path);

/// Reads a dataset (Ece276aFiles) into records merged in time order (scans after the encoder and
/// IMU records with the same stamp, frames after both): encoder counts [FR, FL, RR, RL] become
/// WheelTicks with right {FR, RR} and left {FL, RL}; IMU rows become ImuSamples (rad/s, m/s^2);
/// Hokuyo columns become LaserScans; each disparity image with the RGB image nearest in time
/// becomes an RgbdFrame stamped at the disparity's time (depth = 1.03 / (-0.00304 d + 3.31), 0 =
/// no reading where d is 2047 or the formula gives no positive depth; intrinsics, mounting and
/// depth offset from `options`). Times are unix seconds. There is no reference. Throws ParseError
/// naming the file, array and row for missing arrays, mismatched shapes or non-finite values, and
/// naming the image for a missing or unreadable one or one of the wrong size or type.
Dataset ReadEce276a(const Ece276aFiles& files, const Ece276aReadOptions& options = {});

}  // namespace slamrig::slam
