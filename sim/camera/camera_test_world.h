#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "sim/camera_spec.h"
#include "sim/world_spec.h"

namespace slamrig::sim::testing {

/// Writes a solid-colour (r, g, b) 16 x 16 PNG named `name` into `dir`.
inline void WriteSolidPng(const std::string& dir, const std::string& name, cv::Vec3b rgb) {
  std::filesystem::create_directories(dir);
  cv::imwrite(dir + "/" + name, cv::Mat3b(16, 16, cv::Vec3b(rgb[2], rgb[1], rgb[0])));
}

/// An axis-aligned box shape centred at (cx, cy) with sides (sx, sy), metres.
inline ShapeSpec Box(double cx, double cy, double sx, double sy) {
  ShapeSpec s;
  s.center_m = {cx, cy};
  s.size_m = {sx, sy};
  return s;
}

/// A 6 m x 4 m room (inner faces x in [-1, 5], y in [-2, 2]) with a red zone x in [2, 3],
/// y in [0, 1] (not symmetric, so a mirrored texture shows), as a WorldSpec.
inline WorldSpec SmallRoom() {
  WorldSpec w;
  w.name = "small_room";
  w.walls = {Box(2.0, -2.1, 6.4, 0.2), Box(2.0, 2.1, 6.4, 0.2), Box(-1.1, 0.0, 0.2, 4.0),
             Box(5.1, 0.0, 0.2, 4.0)};
  ZoneSpec zone;
  zone.name = "red rug";
  zone.shape = Box(2.5, 0.5, 1.0, 1.0);
  w.zones = {zone};
  return w;
}

/// A small ideal camera (no noise, no depth offset, principal point at the centre) looking
/// straight ahead from 0.5 m, textures in `texture_dir`: grey floor, red zone.
inline CameraSpec IdealCamera(const std::string& texture_dir) {
  WriteSolidPng(texture_dir, "grey.png", {100, 100, 100});
  WriteSolidPng(texture_dir, "red.png", {200, 30, 30});
  CameraSpec c;
  c.name = "test_cam";
  c.width_px = 161;
  c.height_px = 121;
  c.intrinsics = {150.0, 150.0, 80.0, 60.0};
  c.mount = {0.1, 0.0, 0.5, 0.0, 0.0, 0.0};
  c.depth_offset_x_m = 0.0;
  c.depth_model = DepthModel::kIdeal;
  c.min_depth_m = 0.05;
  c.max_depth_m = 20.0;
  c.texture_dir = texture_dir;
  c.floor_image = "grey.png";
  c.zones = {{"red", "red.png", 1.0}};
  c.wall_image = "";
  c.floor_texel_m = 0.02;
  return c;
}

}  // namespace slamrig::sim::testing
