#pragma once

#include <string>
#include <utility>
#include <vector>

#include "slam/types/rgbd_frame.h"

namespace slamrig::sim {

/// Writes RGB-D frames in the file layout of the ECE276A Kinect data (the reports' texture-mapping
/// input): `dataRGBD/RGB<N>/rgb<N>_<k>.png` (8-bit colour), `dataRGBD/Disparity<N>/
/// disparity<N>_<k>.png` (16-bit raw disparity, k counting from 1), and `Kinect<N>.npz` with the
/// float64 unix-second arrays `rgb_time_stamps` and `disparity_time_stamps`. Disparity is
/// d = round((3.31 - 1.03 / depth) / 0.00304), the inverse of Wang's Eq. 18; pixels without a
/// reading get 2047, the Kinect's no-reading value (the formula gives a negative depth for it).
///
/// The depth image is written in the RGB frame's geometry: same intrinsics, the depth camera
/// `depth_offset_x_m` beside the colour camera. Code that registers the real Kinect's images with
/// the course's IR calibration will be off by that calibration's scale. Every file is written
/// atomically; throws std::runtime_error naming a path that cannot be written.
class KinectLogWriter {
 public:
  /// Writes below `dir` (created if missing) as dataset number `dataset`.
  KinectLogWriter(std::string dir, int dataset);

  /// Writes the next frame's two images.
  void Write(const RgbdFrame& frame);
  /// Writes Kinect<N>.npz with the time stamps of every frame written. Call once at the end.
  void Finish();

  /// Frames written so far.
  int frames() const { return static_cast<int>(stamps_s_.size()); }

 private:
  std::string dir_;
  int dataset_ = 20;
  std::vector<double> stamps_s_;
};

/// A numpy .npz archive (zip, stored) holding one float64 1-D array per (name, values) pair.
std::string MakeNpz(const std::vector<std::pair<std::string, std::vector<double>>>& arrays);

}  // namespace slamrig::sim
