#include "slam/texture/texture_map.h"

#include <cmath>

#include "slam/types/error.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

int TextureMapOptions::width() const {
  return static_cast<int>(std::ceil((max_m.x() - min_m.x()) / resolution_m - 1e-9));
}

int TextureMapOptions::height() const {
  return static_cast<int>(std::ceil((max_m.y() - min_m.y()) / resolution_m - 1e-9));
}

std::vector<std::string> TextureMapOptions::Validate() const {
  Rules rules;
  rules.Require(resolution_m > 0.0 && std::isfinite(resolution_m), "resolution_m", resolution_m,
                "must be > 0");
  // Without a resolution the extents' cell count below means nothing.
  if (!rules.errors().empty()) return PrefixErrors("texture", rules.errors());
  rules.Require(max_m.x() > min_m.x(), "max_m.x", max_m.x(), "must be > texture.min_m.x")
      .Require(max_m.y() > min_m.y(), "max_m.y", max_m.y(), "must be > texture.min_m.y");
  if (rules.errors().empty()) {
    rules.Require(static_cast<double>(width()) * height() <= 1e8, "resolution_m", resolution_m,
                  "gives more than 1e8 cells over the extents");
  }
  rules.Positive("floor_height_threshold_m", floor_height_threshold_m)
      .Positive("max_depth_m", max_depth_m)
      .AtLeast("pixel_stride", pixel_stride, 1);
  return PrefixErrors("texture", rules.errors());
}

TextureMap::TextureMap(const TextureMapOptions& options) : options_(options) {
  const std::vector<std::string> errors = options_.Validate();
  if (!errors.empty()) throw ConfigError(errors.front());
  width_ = options_.width();
  height_ = options_.height();
  sums_.assign(static_cast<std::size_t>(width_) * height_ * 3, 0);
  counts_.assign(static_cast<std::size_t>(width_) * height_, 0);
}

bool TextureMap::CellOf(double x_m, double y_m, int* col, int* row) const {
  const double fx = std::floor((x_m - options_.min_m.x()) / options_.resolution_m);
  const double fy = std::floor((options_.max_m.y() - y_m) / options_.resolution_m);
  if (!(fx >= 0.0 && fx < width_ && fy >= 0.0 && fy < height_)) return false;
  *col = static_cast<int>(fx);
  *row = static_cast<int>(fy);
  return true;
}

Eigen::Vector2d TextureMap::CellCenter(int col, int row) const {
  return {options_.min_m.x() + (col + 0.5) * options_.resolution_m,
          options_.max_m.y() - (row + 0.5) * options_.resolution_m};
}

FloorPixels ExtractFloorPixels(const RgbdFrame& frame, const TextureMapOptions& options) {
  const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
  if (frame.width <= 0 || frame.height <= 0 || frame.rgb.size() != 3 * pixels ||
      frame.depth_m.size() != pixels) {
    throw ConfigError("texture: RGB-D frame of " + std::to_string(frame.width) + " x " +
                      std::to_string(frame.height) + " has " + std::to_string(frame.rgb.size()) +
                      " RGB bytes and " + std::to_string(frame.depth_m.size()) + " depths");
  }
  // The floor is z = 0 of base_link: a planar pose moves it in x, y only.
  const Eigen::Isometry3d base_from_depth = frame.BaseFromDepthOptical();
  const Eigen::Matrix3d rot = base_from_depth.linear();
  const Eigen::Vector3d trans = base_from_depth.translation();
  const CameraIntrinsics& k = frame.intrinsics;
  const double offset = frame.depth_offset_x_m;
  const int stride = options.pixel_stride;

  FloorPixels out;
  out.time = frame.time;
  for (int v = 0; v < frame.height; v += stride) {
    for (int u = 0; u < frame.width; u += stride) {
      const double z = frame.depth_m[static_cast<std::size_t>(v) * frame.width + u];
      if (!(z > 0.0) || z > options.max_depth_m) continue;
      ++out.depth_readings;
      // Back-project in the depth camera's optical frame, then to base_link.
      const Eigen::Vector3d p_depth((u - k.cx_px) / k.fx_px * z, (v - k.cy_px) / k.fy_px * z, z);
      const Eigen::Vector3d p_base = rot * p_depth + trans;
      if (std::abs(p_base.z()) > options.floor_height_threshold_m) continue;
      // The same point in the RGB optical frame (same orientation, origin -offset along x).
      const double xr = p_depth.x() + offset;
      const double ur = std::round(k.fx_px * xr / z + k.cx_px);
      const double vr = std::round(k.fy_px * p_depth.y() / z + k.cy_px);
      if (!(ur >= 0.0 && ur < frame.width && vr >= 0.0 && vr < frame.height)) continue;
      const std::size_t src =
          3 * (static_cast<std::size_t>(vr) * frame.width + static_cast<std::size_t>(ur));
      out.base_xy_m.emplace_back(static_cast<float>(p_base.x()), static_cast<float>(p_base.y()));
      out.rgb.push_back({frame.rgb[src], frame.rgb[src + 1], frame.rgb[src + 2]});
    }
  }
  return out;
}

int TextureMap::Insert(const RgbdFrame& frame, const Pose2& map_from_base) {
  return Insert(ExtractFloorPixels(frame, options_), map_from_base);
}

int TextureMap::Insert(const FloorPixels& pixels, const Pose2& map_from_base) {
  const double c = std::cos(map_from_base.theta()), s = std::sin(map_from_base.theta());
  int added = 0;
  for (std::size_t i = 0; i < pixels.base_xy_m.size(); ++i) {
    const double bx = pixels.base_xy_m[i].x(), by = pixels.base_xy_m[i].y();
    int col = 0, row = 0;
    if (!CellOf(map_from_base.x() + c * bx - s * by, map_from_base.y() + s * bx + c * by, &col,
                &row)) {
      continue;
    }
    const std::size_t cell = static_cast<std::size_t>(row) * width_ + col;
    for (int k = 0; k < 3; ++k) sums_[3 * cell + k] += pixels.rgb[i][k];
    ++counts_[cell];
    ++added;
  }
  return added;
}

cv::Mat3b TextureMap::Colors() const {
  cv::Mat3b out(height_, width_, cv::Vec3b(0, 0, 0));
  for (int row = 0; row < height_; ++row) {
    for (int col = 0; col < width_; ++col) {
      const std::size_t cell = static_cast<std::size_t>(row) * width_ + col;
      const std::uint32_t n = counts_[cell];
      if (n == 0) continue;
      for (int c = 0; c < 3; ++c) {
        out(row, col)[c] = static_cast<std::uint8_t>((sums_[3 * cell + c] + n / 2) / n);
      }
    }
  }
  return out;
}

cv::Mat1b TextureMap::Observed() const {
  cv::Mat1b out(height_, width_, std::uint8_t{0});
  for (int row = 0; row < height_; ++row) {
    for (int col = 0; col < width_; ++col) {
      if (counts_[static_cast<std::size_t>(row) * width_ + col] > 0) out(row, col) = 255;
    }
  }
  return out;
}

}  // namespace slamrig::slam
