#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/rgbd_frame.h"
#include "slam/types/time.h"

namespace slamrig::slam {

/// Where the colour map lies and which pixels are floor.
struct TextureMapOptions {
  double resolution_m = 0.05;                           ///< cell side
  Eigen::Vector2d min_m = Eigen::Vector2d(0.0, 0.0);    ///< lower-left corner (map frame)
  Eigen::Vector2d max_m = Eigen::Vector2d(10.0, 10.0);  ///< upper-right corner
  /// A back-projected depth pixel is floor when its height in the map frame is within this of 0
  /// (Wang, ECE276A report, Fig. 4, thresholds at 0.15 m on the real robot).
  double floor_height_threshold_m = 0.05;
  double max_depth_m = 5.0;  ///< farther depth readings are ignored
  int pixel_stride = 1;      ///< use every n-th depth pixel along rows and columns

  /// Columns of the raster.
  int width() const;
  /// Rows of the raster.
  int height() const;
  /// One message per broken rule ("texture.resolution_m = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

/// The floor pixels of one RGB-D frame in base_link's floor plane, with their colours. Which
/// pixels are floor does not depend on the robot's planar pose (only on the camera's mounting), so
/// a frame is reduced to these once and mapped with any estimator's pose later: a few hundred
/// kilobytes instead of the frame's megabytes.
struct FloorPixels {
  Time time;                                     ///< the frame's time
  std::vector<Eigen::Vector2f> base_xy_m;        ///< floor points in base_link, metres
  std::vector<std::array<std::uint8_t, 3>> rgb;  ///< their colours (r, g, b), one per point
  int depth_readings = 0;  ///< depth pixels with a reading in range (floor or not)
};

/// The floor pixels of `frame` (every `options.pixel_stride`-th depth pixel along rows and
/// columns): back-projected from the depth camera, kept when their height is within
/// `floor_height_threshold_m` of the floor and the RGB camera sees them, coloured by projecting
/// them into the RGB image (the two cameras are offset). Throws ConfigError for a frame whose
/// image sizes disagree.
FloorPixels ExtractFloorPixels(const RgbdFrame& frame, const TextureMapOptions& options);

/// A floor colour map: RGB-D floor pixels projected through the robot's pose into a raster that
/// keeps the mean colour per cell (Zafari, ECE276A report, "Texture Mapping", Eq. 8: a pixel with
/// depth goes optical frame -> body -> world; Wang, ECE276A report, Fig. 4: floor pixels are those
/// whose world height is near 0). Works with the poses of any estimator. Raster row 0 is the
/// top (largest y), column 0 the smallest x, so the images save north-up.
class TextureMap {
 public:
  /// An empty map; throws ConfigError when `options` break a rule.
  explicit TextureMap(const TextureMapOptions& options);

  const TextureMapOptions& options() const { return options_; }

  /// Adds the floor pixels of `frame` taken at `map_from_base`. Each depth pixel is back-projected
  /// from the depth camera, kept when it is floor and inside the raster, and coloured by projecting
  /// it into the RGB camera (the depth and RGB cameras are offset). Returns the pixels added.
  int Insert(const RgbdFrame& frame, const Pose2& map_from_base);
  /// Adds floor pixels taken at `map_from_base` (those inside the raster); returns their number.
  /// Insert(frame, pose) is Insert(ExtractFloorPixels(frame, options()), pose).
  int Insert(const FloorPixels& pixels, const Pose2& map_from_base);

  /// The cell holding map point (x, y), or false when it is outside.
  bool CellOf(double x_m, double y_m, int* col, int* row) const;
  /// The centre of cell (col, row) in the map frame.
  Eigen::Vector2d CellCenter(int col, int row) const;

  /// Mean colour per cell (r, g, b channel order), black where nothing was seen.
  cv::Mat3b Colors() const;
  /// 255 where a cell received at least one pixel, else 0.
  cv::Mat1b Observed() const;

 private:
  TextureMapOptions options_;
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint64_t> sums_;  ///< r, g, b sums per cell, row-major
  std::vector<std::uint32_t> counts_;
};

}  // namespace slamrig::slam
