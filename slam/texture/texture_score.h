#pragma once

#include <opencv2/core.hpp>
#include <optional>

namespace slamrig::slam {

/// How well a floor colour map matches the true floor texture.
struct TextureScore {
  int floor_cells = 0;     ///< cells of the truth that are floor
  int observed_cells = 0;  ///< floor cells the map observed
  double coverage = 0.0;   ///< observed_cells / floor_cells (0 when there is no floor)
  /// Mean absolute error per channel over observed floor cells, in 0..255; none when nothing
  /// was observed.
  std::optional<double> mean_abs_error;
  /// Peak signal-to-noise ratio, 10 log10(255^2 / MSE) over the same cells and channels, in dB;
  /// +infinity for identical colours, none when nothing was observed.
  std::optional<double> psnr_db;
};

/// Scores `colors` (observed where `observed` is non-zero) against the truth raster `truth`
/// (floor where `truth_floor` is non-zero). All four rasters must have the same size; throws
/// std::invalid_argument when they do not.
TextureScore ScoreTexture(const cv::Mat3b& colors, const cv::Mat1b& observed,
                          const cv::Mat3b& truth, const cv::Mat1b& truth_floor);

}  // namespace slamrig::slam
