#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sim/camera_spec.h"
#include "sim/shape_spec.h"
#include "sim/world_spec.h"
#include "slam/texture/texture_map.h"

namespace slamrig::sim {

/// Every static wall of `world`: its walls and the boxes of its imported map (read from disk).
std::vector<ShapeSpec> StaticWalls(const WorldSpec& world);

/// The image `image` named by field `field` of `camera` (relative to camera.texture_dir, by
/// default worlds/textures), r, g, b channel order; throws ParseError naming the file and the
/// field when it is missing or not an image.
cv::Mat3b ReadTextureImage(const CameraSpec& camera, const std::string& image,
                           const std::string& field);

/// The true floor texture of a world as the camera renders it: the zones' images (tiled, `tile_m`
/// per copy, later zones winning) composed over the floor image into one texture of
/// `floor_texel_m` texels that covers the walls' bounding box plus a margin. MuJoCo draws it on one
/// floor plane, and the same texels give the truth a texture map is scored against.
class FloorTexture {
 public:
  /// Reads the images; throws ParseError naming a missing or unreadable file, and ConfigError for
  /// a texture too large for the renderer.
  FloorTexture(const WorldSpec& world, const CameraSpec& camera);

  /// The composed texture, r, g, b channel order; row 0 is the largest y, column 0 the smallest x.
  const cv::Mat3b& image() const { return image_; }
  /// Lower-left corner of the texture in the map frame.
  const Eigen::Vector2d& min_m() const { return min_m_; }
  /// Upper-right corner.
  const Eigen::Vector2d& max_m() const { return max_m_; }
  /// The texel side, metres.
  double texel_m() const { return texel_m_; }
  /// The walls the texture was laid out for.
  const std::vector<ShapeSpec>& walls() const { return walls_; }

  /// The texel colour at map point `p` (the nearest texel; black outside the texture).
  cv::Vec3b ColorAt(const Eigen::Vector2d& p) const;

  /// The truth raster for a texture map laid out by `options`: each cell the mean of 4 x 4 samples
  /// of ColorAt over its area.
  cv::Mat3b TruthColors(const slam::TextureMapOptions& options) const;
  /// 255 where a cell of that raster is floor (its centre inside the texture and in no wall).
  cv::Mat1b FloorMask(const slam::TextureMapOptions& options) const;

 private:
  std::vector<ShapeSpec> walls_;
  cv::Mat3b image_;
  Eigen::Vector2d min_m_;
  Eigen::Vector2d max_m_;
  double texel_m_ = 0.02;
};

}  // namespace slamrig::sim
