#include "sim/camera_spec.h"

#include <cmath>

#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> CameraSpec::Validate() const {
  std::vector<std::string> e;
  const std::string p;  // the robot file prefixes "camera."
  const auto positive = [&](const std::string& field, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) e.push_back(RuleViolation(p + field, v, "must be > 0"));
  };
  const auto non_negative = [&](const std::string& field, double v) {
    if (!(v >= 0.0) || !std::isfinite(v)) e.push_back(RuleViolation(p + field, v, "must be >= 0"));
  };
  if (name.empty()) e.push_back(RuleViolation(p + "name", "''", "must not be empty"));
  if (width_px < 1 || width_px > 4096) {
    e.push_back(RuleViolation(p + "width_px", width_px, "must be in [1, 4096]"));
  }
  if (height_px < 1 || height_px > 4096) {
    e.push_back(RuleViolation(p + "height_px", height_px, "must be in [1, 4096]"));
  }
  positive("rate_hz", rate_hz);
  positive("intrinsics.fx_px", intrinsics.fx_px);
  positive("intrinsics.fy_px", intrinsics.fy_px);
  if (intrinsics.fx_px != intrinsics.fy_px) {
    e.push_back(RuleViolation(p + "intrinsics.fx_px", intrinsics.fx_px,
                              "must equal intrinsics.fy_px (MuJoCo 2.2 renders square pixels)"));
  }
  const auto inside = [&](const std::string& field, double v, int size) {
    if (!(v >= 0.0 && v <= size - 1)) {
      e.push_back(RuleViolation(p + field, v,
                                "must lie in the image, [0, " + std::to_string(size - 1) + "]"));
    }
  };
  inside("intrinsics.cx_px", intrinsics.cx_px, width_px);
  inside("intrinsics.cy_px", intrinsics.cy_px, height_px);
  if (!std::isfinite(depth_offset_x_m) || std::abs(depth_offset_x_m) > 0.5) {
    e.push_back(RuleViolation(p + "depth_offset_x_m", depth_offset_x_m, "must be in [-0.5, 0.5]"));
  }
  non_negative("disparity_noise_stddev", disparity_noise_stddev);
  positive("min_depth_m", min_depth_m);
  if (!(max_depth_m > min_depth_m)) {
    e.push_back(RuleViolation(p + "max_depth_m", max_depth_m, "must be > min_depth_m"));
  }
  non_negative("rgb_noise_stddev", rgb_noise_stddev);
  if (floor_image.empty()) e.push_back(RuleViolation(p + "floor_image", "''", "must name a PNG"));
  positive("floor_tile_m", floor_tile_m);
  for (std::size_t i = 0; i < zones.size(); ++i) {
    const std::string z = p + "zones[" + std::to_string(i) + "].";
    if (zones[i].zone.empty()) e.push_back(RuleViolation(z + "zone", "''", "must name a zone"));
    if (zones[i].image.empty()) e.push_back(RuleViolation(z + "image", "''", "must name a PNG"));
    positive("zones[" + std::to_string(i) + "].tile_m", zones[i].tile_m);
  }
  positive("floor_texel_m", floor_texel_m);
  positive("wall_height_m", wall_height_m);
  for (int c = 0; c < 3; ++c) {
    if (!(wall_rgb[c] >= 0.0 && wall_rgb[c] <= 1.0)) {
      e.push_back(RuleViolation(p + "wall_rgb[" + std::to_string(c) + "]", wall_rgb[c],
                                "must be in [0, 1]"));
    }
  }
  positive("wall_tile_m", wall_tile_m);
  positive("znear_m", znear_m);
  if (!(zfar_m > znear_m)) e.push_back(RuleViolation(p + "zfar_m", zfar_m, "must be > znear_m"));
  if (!(max_depth_m < zfar_m)) {
    e.push_back(RuleViolation(p + "max_depth_m", max_depth_m, "must be < zfar_m"));
  }
  return e;
}

}  // namespace slamrig::sim
