// Likelihood-field range finder model: Thrun, Burgard, Fox, "Probabilistic Robotics" (2005),
// Sec. 6.4, Table 6.3 (z_hit Gaussian of the distance to the nearest obstacle plus z_rand).
#include "slam/matching/likelihood_field.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> LikelihoodFieldOptions::Validate() const {
  std::vector<std::string> errors;
  auto add = [&](const char* field, double got, const char* rule) {
    errors.push_back(RuleViolation(field, got, rule));
  };
  if (!(sigma_m > 0.0)) add("sigma_m", sigma_m, "must be > 0");
  if (!(z_hit > 0.0)) add("z_hit", z_hit, "must be > 0");
  if (!(z_rand > 0.0)) add("z_rand", z_rand, "must be > 0");
  if (!(cutoff_sigmas > 0.0)) add("cutoff_sigmas", cutoff_sigmas, "must be > 0");
  return errors;
}

LikelihoodField::LikelihoodField(const LikelihoodFieldOptions& options) : options_(options) {
  SLAMRIG_CHECK(options_.Validate().empty(), "invalid LikelihoodFieldOptions");
}

double LikelihoodField::Score(double distance_m) const {
  if (distance_m > options_.cutoff_sigmas * options_.sigma_m * (1.0 + 1e-9)) return 0.0;
  const double g = std::exp(-0.5 * distance_m * distance_m / (options_.sigma_m * options_.sigma_m));
  return std::log(options_.z_hit * g + options_.z_rand) - std::log(options_.z_rand);
}

void LikelihoodField::Update(const OccupancyGrid& grid, const Eigen::AlignedBox2d& region) {
  resolution_ = grid.resolution();
  // Kernel of scores by cell offset, rebuilt only when the resolution changes.
  if (kernel_resolution_ != resolution_) {
    kernel_resolution_ = resolution_;
    radius_cells_ =
        static_cast<int>(std::ceil(options_.cutoff_sigmas * options_.sigma_m / resolution_));
    const int side = 2 * radius_cells_ + 1;
    kernel_.assign(static_cast<std::size_t>(side * side), 0.0f);
    for (int dy = -radius_cells_; dy <= radius_cells_; ++dy) {
      for (int dx = -radius_cells_; dx <= radius_cells_; ++dx) {
        kernel_[static_cast<std::size_t>((dy + radius_cells_) * side + dx + radius_cells_)] =
            static_cast<float>(Score(std::hypot(dx, dy) * resolution_));
      }
    }
  }
  // Window on the grid lattice, clipped to the grid.
  const Eigen::Array2i lo = grid.WorldToCell(region.min()).max(Eigen::Array2i(0, 0));
  const Eigen::Array2i hi =
      grid.WorldToCell(region.max()).min(Eigen::Array2i(grid.width() - 1, grid.height() - 1));
  width_ = std::max(0, hi.x() - lo.x() + 1);
  height_ = std::max(0, hi.y() - lo.y() + 1);
  origin_ = grid.origin() + lo.cast<double>().matrix() * resolution_;
  values_.assign(static_cast<std::size_t>(width_) * height_, 0.0f);
  if (width_ == 0 || height_ == 0) return;

  // Stamp the kernel (max) around every wall cell within reach of the window.
  const int r = radius_cells_;
  const int side = 2 * r + 1;
  const std::vector<float>& log_odds = grid.log_odds();
  const int y_begin = std::max(0, lo.y() - r), y_end = std::min(grid.height(), hi.y() + r + 1);
  const int x_begin = std::max(0, lo.x() - r), x_end = std::min(grid.width(), hi.x() + r + 1);
  for (int gy = y_begin; gy < y_end; ++gy) {
    const float* row = log_odds.data() + static_cast<std::ptrdiff_t>(gy) * grid.width();
    for (int gx = x_begin; gx < x_end; ++gx) {
      if (!(row[gx] > options_.occupied_threshold)) continue;
      const int wx = gx - lo.x(), wy = gy - lo.y();
      const int dy0 = std::max(-r, -wy), dy1 = std::min(r, height_ - 1 - wy);
      const int dx0 = std::max(-r, -wx), dx1 = std::min(r, width_ - 1 - wx);
      for (int dy = dy0; dy <= dy1; ++dy) {
        float* out = values_.data() + static_cast<std::ptrdiff_t>(wy + dy) * width_ + wx;
        const float* k = kernel_.data() + static_cast<std::ptrdiff_t>(dy + r) * side + r;
        for (int dx = dx0; dx <= dx1; ++dx) out[dx] = std::max(out[dx], k[dx]);
      }
    }
  }
}

GridView LikelihoodField::view() const {
  return GridView{values_.data(), width_, height_, origin_, resolution_};
}

}  // namespace slamrig::slam
