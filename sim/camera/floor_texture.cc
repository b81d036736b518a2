#include "sim/camera/floor_texture.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/map_import.h"
#include "slam/io/map_server.h"
#include "slam/types/error.h"

namespace slamrig::sim {
namespace {

constexpr double kMarginM = 1.0;  // floor beyond the outermost wall
constexpr int kMaxTexels = 8192;  // per side; llvmpipe allows 16384

std::string TexturePath(const CameraSpec& camera, const std::string& image) {
  if (std::filesystem::path(image).is_absolute()) return image;
  const std::string dir = camera.texture_dir.empty()
                              ? std::string(SLAMRIG_SOURCE_DIR) + "/worlds/textures"
                              : camera.texture_dir;
  return (std::filesystem::path(dir) / image).string();
}

}  // namespace

cv::Mat3b ReadTextureImage(const CameraSpec& camera, const std::string& image,
                           const std::string& field) {
  const std::string path = TexturePath(camera, image);
  if (!std::filesystem::exists(path)) {
    throw ParseError(path + ": " + field + ": texture file not found");
  }
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) throw ParseError(path + ": " + field + ": not an image OpenCV can read");
  cv::Mat3b rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

namespace {

// The texel of `tile` (one copy covering tile_m x tile_m, image row 0 at the top) at map point p.
cv::Vec3b TileColor(const cv::Mat3b& tile, double tile_m, const Eigen::Vector2d& p) {
  const double fu = p.x() / tile_m - std::floor(p.x() / tile_m);
  const double fv = 1.0 - (p.y() / tile_m - std::floor(p.y() / tile_m));
  const int col = std::clamp(static_cast<int>(fu * tile.cols), 0, tile.cols - 1);
  const int row = std::clamp(static_cast<int>(fv * tile.rows), 0, tile.rows - 1);
  return tile(row, col);
}

void Extend(const Eigen::Vector2d& p, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  *lo = lo->cwiseMin(p);
  *hi = hi->cwiseMax(p);
}

}  // namespace

std::vector<ShapeSpec> StaticWalls(const WorldSpec& world) {
  std::vector<ShapeSpec> walls = world.walls;
  if (world.map) {
    const slam::MapImage map = slam::ReadMapServerMap(world.map->yaml_path);
    const std::vector<ShapeSpec> boxes = MapWallBoxes(map, *world.map);
    walls.insert(walls.end(), boxes.begin(), boxes.end());
  }
  return walls;
}

FloorTexture::FloorTexture(const WorldSpec& world, const CameraSpec& camera)
    : walls_(StaticWalls(world)), texel_m_(camera.floor_texel_m) {
  // Extents: every wall and zone, else the spawn point; plus the margin.
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Vector2d lo(inf, inf), hi(-inf, -inf);
  Extend(world.spawn.translation(), &lo, &hi);
  const auto extend_shape = [&](const ShapeSpec& s) {
    if (s.type == ShapeType::kCircle) {
      Extend(s.center_m - Eigen::Vector2d::Constant(s.radius_m), &lo, &hi);
      Extend(s.center_m + Eigen::Vector2d::Constant(s.radius_m), &lo, &hi);
    } else if (s.type == ShapeType::kPolyline) {
      for (const Eigen::Vector2d& p : s.points_m) Extend(p, &lo, &hi);
    } else {
      for (const Eigen::Vector2d& p : s.Outline()) Extend(p, &lo, &hi);
    }
  };
  for (const ShapeSpec& s : walls_) extend_shape(s);
  for (const ZoneSpec& z : world.zones) extend_shape(z.shape);
  min_m_ = lo - Eigen::Vector2d::Constant(kMarginM);
  const int cols = static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * kMarginM) / texel_m_));
  const int rows = static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * kMarginM) / texel_m_));
  if (cols > kMaxTexels || rows > kMaxTexels) {
    throw ConfigError("camera '" + camera.name + "': floor_texel_m = " + std::to_string(texel_m_) +
                      " gives a " + std::to_string(cols) + " x " + std::to_string(rows) +
                      " floor texture for world '" + world.name + "'; the renderer allows " +
                      std::to_string(kMaxTexels) + " per side, use larger texels");
  }
  max_m_ = min_m_ + Eigen::Vector2d(cols * texel_m_, rows * texel_m_);

  // The images, and for each zone its texture (or none).
  const cv::Mat3b floor = ReadTextureImage(camera, camera.floor_image, "camera.floor_image");
  std::vector<cv::Mat3b> zone_images(world.zones.size());
  std::vector<double> zone_tiles(world.zones.size(), 0.0);
  for (std::size_t i = 0; i < camera.zones.size(); ++i) {
    const ZoneTexture& zt = camera.zones[i];
    const std::string field = "camera.zones[" + std::to_string(i) + "]";
    for (std::size_t z = 0; z < world.zones.size(); ++z) {
      if (world.zones[z].name.find(zt.zone) == std::string::npos) continue;
      zone_images[z] = ReadTextureImage(camera, zt.image, field + ".image");
      zone_tiles[z] = zt.tile_m;
    }
  }

  // Compose: each texel takes the last zone containing its centre, else the floor.
  image_.create(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d p(min_m_.x() + (c + 0.5) * texel_m_, max_m_.y() - (r + 0.5) * texel_m_);
      cv::Vec3b color = TileColor(floor, camera.floor_tile_m, p);
      for (std::size_t z = world.zones.size(); z-- > 0;) {
        if (zone_images[z].empty() || !world.zones[z].shape.Contains(p)) continue;
        color = TileColor(zone_images[z], zone_tiles[z], p);
        break;
      }
      image_(r, c) = color;
    }
  }
}

cv::Vec3b FloorTexture::ColorAt(const Eigen::Vector2d& p) const {
  const double fc = std::floor((p.x() - min_m_.x()) / texel_m_);
  const double fr = std::floor((max_m_.y() - p.y()) / texel_m_);
  if (!(fc >= 0 && fc < image_.cols && fr >= 0 && fr < image_.rows)) return {0, 0, 0};
  return image_(static_cast<int>(fr), static_cast<int>(fc));
}

cv::Mat3b FloorTexture::TruthColors(const slam::TextureMapOptions& options) const {
  constexpr int kSamples = 4;
  const int w = options.width(), h = options.height();
  cv::Mat3b out(h, w);
  const double res = options.resolution_m;
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      int sum[3] = {0, 0, 0};
      for (int i = 0; i < kSamples; ++i) {
        for (int j = 0; j < kSamples; ++j) {
          const Eigen::Vector2d p(options.min_m.x() + (c + (j + 0.5) / kSamples) * res,
                                  options.max_m.y() - (r + (i + 0.5) / kSamples) * res);
          const cv::Vec3b v = ColorAt(p);
          for (int k = 0; k < 3; ++k) sum[k] += v[k];
        }
      }
      constexpr int n = kSamples * kSamples;
      for (int k = 0; k < 3; ++k) out(r, c)[k] = static_cast<std::uint8_t>((sum[k] + n / 2) / n);
    }
  }
  return out;
}

cv::Mat1b FloorTexture::FloorMask(const slam::TextureMapOptions& options) const {
  const int w = options.width(), h = options.height();
  cv::Mat1b out(h, w, std::uint8_t{0});
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const Eigen::Vector2d p(options.min_m.x() + (c + 0.5) * options.resolution_m,
                              options.max_m.y() - (r + 0.5) * options.resolution_m);
      if (p.x() < min_m_.x() || p.x() > max_m_.x() || p.y() < min_m_.y() || p.y() > max_m_.y()) {
        continue;
      }
      const bool in_wall = std::any_of(walls_.begin(), walls_.end(),
                                       [&](const ShapeSpec& s) { return s.Contains(p); });
      if (!in_wall) out(r, c) = 255;
    }
  }
  return out;
}

}  // namespace slamrig::sim
