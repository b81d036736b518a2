#include "sim/camera_spec.h"

#include <cmath>

#include "slam/types/validation.h"

namespace slamrig::sim {

std::vector<std::string> CameraSpec::Validate() const {
  // Keys are relative to the camera (the robot file prefixes "camera."); its lengths and rates
  // must also be finite (MuJoCo gets them).
  Rules rules;
  const auto positive = [&](const std::string& field, double v) {
    rules.Require(v > 0.0 && std::isfinite(v), field, v, "must be > 0");
  };
  const auto non_negative = [&](const std::string& field, double v) {
    rules.Require(v >= 0.0 && std::isfinite(v), field, v, "must be >= 0");
  };
  rules.Require(!name.empty(), "name", "''", "must not be empty")
      .InRange("width_px", width_px, 1, 4096)
      .InRange("height_px", height_px, 1, 4096);
  positive("rate_hz", rate_hz);
  positive("intrinsics.fx_px", intrinsics.fx_px);
  positive("intrinsics.fy_px", intrinsics.fy_px);
  rules.Require(intrinsics.fx_px == intrinsics.fy_px, "intrinsics.fx_px", intrinsics.fx_px,
                "must equal intrinsics.fy_px (MuJoCo 2.2 renders square pixels)");
  const auto inside = [&](const std::string& field, double v, int size) {
    rules.Require(v >= 0.0 && v <= size - 1, field, v,
                  "must lie in the image, [0, " + std::to_string(size - 1) + "]");
  };
  inside("intrinsics.cx_px", intrinsics.cx_px, width_px);
  inside("intrinsics.cy_px", intrinsics.cy_px, height_px);
  rules.InRange("depth_offset_x_m", depth_offset_x_m, -0.5, 0.5);
  non_negative("disparity_noise_stddev", disparity_noise_stddev);
  positive("min_depth_m", min_depth_m);
  rules.Require(max_depth_m > min_depth_m, "max_depth_m", max_depth_m, "must be > min_depth_m");
  non_negative("rgb_noise_stddev", rgb_noise_stddev);
  rules.Require(!floor_image.empty(), "floor_image", "''", "must name a PNG");
  positive("floor_tile_m", floor_tile_m);
  for (std::size_t i = 0; i < zones.size(); ++i) {
    const std::string z = "zones[" + std::to_string(i) + "].";
    rules.Require(!zones[i].zone.empty(), z + "zone", "''", "must name a zone")
        .Require(!zones[i].image.empty(), z + "image", "''", "must name a PNG");
    positive(z + "tile_m", zones[i].tile_m);
  }
  positive("floor_texel_m", floor_texel_m);
  positive("wall_height_m", wall_height_m);
  for (int c = 0; c < 3; ++c) {
    rules.Fraction("wall_rgb[" + std::to_string(c) + "]", wall_rgb[c]);
  }
  positive("wall_tile_m", wall_tile_m);
  positive("znear_m", znear_m);
  rules.Require(zfar_m > znear_m, "zfar_m", zfar_m, "must be > znear_m")
      .Require(max_depth_m < zfar_m, "max_depth_m", max_depth_m, "must be < zfar_m");
  return rules.errors();
}

}  // namespace slamrig::sim
