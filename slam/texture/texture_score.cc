#include "slam/texture/texture_score.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace slamrig::slam {

TextureScore ScoreTexture(const cv::Mat3b& colors, const cv::Mat1b& observed,
                          const cv::Mat3b& truth, const cv::Mat1b& truth_floor) {
  if (colors.size() != observed.size() || colors.size() != truth.size() ||
      colors.size() != truth_floor.size()) {
    throw std::invalid_argument(
        "ScoreTexture: the colour map, its mask, the truth and the floor "
        "mask must have the same size");
  }
  TextureScore score;
  double abs_sum = 0.0;
  double sq_sum = 0.0;
  for (int row = 0; row < truth.rows; ++row) {
    for (int col = 0; col < truth.cols; ++col) {
      if (truth_floor(row, col) == 0) continue;
      ++score.floor_cells;
      if (observed(row, col) == 0) continue;
      ++score.observed_cells;
      for (int c = 0; c < 3; ++c) {
        const double d = static_cast<double>(colors(row, col)[c]) - truth(row, col)[c];
        abs_sum += std::abs(d);
        sq_sum += d * d;
      }
    }
  }
  if (score.floor_cells > 0) {
    score.coverage = static_cast<double>(score.observed_cells) / score.floor_cells;
  }
  if (score.observed_cells > 0) {
    const double n = 3.0 * score.observed_cells;
    score.mean_abs_error = abs_sum / n;
    const double mse = sq_sum / n;
    score.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse)
                              : std::numeric_limits<double>::infinity();
  }
  return score;
}

}  // namespace slamrig::slam
