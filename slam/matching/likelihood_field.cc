// Likelihood-field range finder model: Thrun, Burgard, Fox, "Probabilistic Robotics" (2005),
// Sec. 6.4, Table 6.3 (z_hit Gaussian of the distance to the nearest obstacle plus z_rand).
#include "slam/matching/likelihood_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> LikelihoodFieldOptions::Validate() const {
  Rules rules;
  rules.Positive("sigma_m", sigma_m)
      .Positive("z_hit", z_hit)
      .Positive("z_rand", z_rand)
      .Positive("cutoff_sigmas", cutoff_sigmas);
  return rules.errors();
}

LikelihoodField::LikelihoodField(const LikelihoodFieldOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "LikelihoodFieldOptions");
}

double LikelihoodField::Score(double distance_m) const {
  if (distance_m > options_.cutoff_sigmas * options_.sigma_m * (1.0 + 1e-9)) return 0.0;
  const double g = std::exp(-0.5 * distance_m * distance_m / (options_.sigma_m * options_.sigma_m));
  return std::log(options_.z_hit * g + options_.z_rand) - std::log(options_.z_rand);
}

double LikelihoodField::Distance(double score) const {
  if (!(score > 0.0)) return std::numeric_limits<double>::infinity();
  // score = log(z_hit g + z_rand) - log(z_rand), g = exp(-d^2 / (2 sigma^2)).
  const double g = std::min(1.0, options_.z_rand * std::expm1(score) / options_.z_hit);
  return options_.sigma_m * std::sqrt(-2.0 * std::log(g));
}

void LikelihoodField::SetSigma(double sigma_m) {
  SLAMRIG_CHECK(sigma_m > 0.0, "LikelihoodField::SetSigma needs sigma_m > 0");
  if (sigma_m == options_.sigma_m) return;
  options_.sigma_m = sigma_m;
  kernel_resolution_ = 0.0;  // the kernel is rebuilt
  followed_ = nullptr;       // and the followed field recomputed everywhere
}

void LikelihoodField::EnsureKernel(double resolution) {
  resolution_ = resolution;
  // Kernel of scores by cell offset, rebuilt only when the resolution changes.
  if (kernel_resolution_ == resolution_) return;
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

void LikelihoodField::Fill(const OccupancyGrid& grid, const Eigen::Array2i& lo,
                           const Eigen::Array2i& hi, float* out, int stride) const {
  const int width = hi.x() - lo.x() + 1, height = hi.y() - lo.y() + 1;
  if (width <= 0 || height <= 0) return;
  for (int y = 0; y < height; ++y) {
    std::fill_n(out + static_cast<std::ptrdiff_t>(y) * stride, width, 0.0f);
  }
  // Stamp the kernel (max) around every wall cell within reach of the box. A max is exact and
  // order-free, so any box gives its cells the values of a whole-grid pass.
  const int r = radius_cells_;
  const int side = 2 * r + 1;
  const int y_begin = std::max(0, lo.y() - r), y_end = std::min(grid.height(), hi.y() + r + 1);
  const int x_begin = std::max(0, lo.x() - r), x_end = std::min(grid.width(), hi.x() + r + 1);
  if (x_end <= x_begin) return;
  thread_local std::vector<float> row;
  row.resize(static_cast<std::size_t>(x_end - x_begin));
  for (int gy = y_begin; gy < y_end; ++gy) {
    grid.CopyLogOdds({x_begin, gy}, {x_end - x_begin, 1}, row.data(), 0);
    for (int gx = x_begin; gx < x_end; ++gx) {
      if (!(row[static_cast<std::size_t>(gx - x_begin)] > options_.occupied_threshold)) continue;
      const int wx = gx - lo.x(), wy = gy - lo.y();
      const int dy0 = std::max(-r, -wy), dy1 = std::min(r, height - 1 - wy);
      const int dx0 = std::max(-r, -wx), dx1 = std::min(r, width - 1 - wx);
      for (int dy = dy0; dy <= dy1; ++dy) {
        float* o = out + static_cast<std::ptrdiff_t>(wy + dy) * stride + wx;
        const float* k = kernel_.data() + static_cast<std::ptrdiff_t>(dy + r) * side + r;
        for (int dx = dx0; dx <= dx1; ++dx) o[dx] = std::max(o[dx], k[dx]);
      }
    }
  }
}

void LikelihoodField::Update(const OccupancyGrid& grid, const Eigen::AlignedBox2d& region) {
  followed_ = nullptr;
  EnsureKernel(grid.resolution());
  // Window on the grid lattice, clipped to the grid.
  const auto [lo, hi] = grid.CellsIn(region);
  width_ = std::max(0, hi.x() - lo.x() + 1);
  height_ = std::max(0, hi.y() - lo.y() + 1);
  origin_ = grid.origin() + lo.cast<double>().matrix() * resolution_;
  values_.assign(static_cast<std::size_t>(width_) * height_, 0.0f);
  Fill(grid, lo, hi, values_.data(), width_);
}

void LikelihoodField::Refill(const OccupancyGrid& grid, Eigen::Array2i lo, Eigen::Array2i hi) {
  lo = lo.max(Eigen::Array2i(0, 0));
  hi = hi.min(Eigen::Array2i(width_ - 1, height_ - 1));
  if ((lo > hi).any()) return;
  Fill(grid, lo + window_lo_, hi + window_lo_,
       values_.data() + static_cast<std::ptrdiff_t>(lo.y()) * width_ + lo.x(), width_);
}

std::pair<Eigen::Array2i, Eigen::Array2i> LikelihoodField::GridCells(
    const Eigen::AlignedBox2d& region) const {
  // OccupancyGrid::WorldToCell on the followed grid's lattice.
  const auto cell = [&](const Eigen::Vector2d& p) {
    return Eigen::Array2i(static_cast<int>(std::floor((p.x() - grid_origin_.x()) / resolution_)),
                          static_cast<int>(std::floor((p.y() - grid_origin_.y()) / resolution_)));
  };
  return {cell(region.min()).max(Eigen::Array2i(0, 0)),
          cell(region.max()).min(grid_size_ - Eigen::Array2i(1, 1))};
}

void LikelihoodField::Recompute(const OccupancyGrid& grid, const Eigen::AlignedBox2d& region) {
  grid_origin_ = grid.origin();
  grid_size_ = {grid.width(), grid.height()};
  auto [lo, hi] = GridCells(region);
  // Slack: a quarter of the region's side (at least 64 cells) on every side, so that a robot
  // moving on redoes the window every few metres, not every scan.
  const int slack = std::max(64, ((hi - lo).maxCoeff() + 1) / 4);
  lo = (lo - slack).max(Eigen::Array2i(0, 0));
  hi = (hi + slack).min(grid_size_ - Eigen::Array2i(1, 1));
  window_lo_ = lo;
  width_ = std::max(0, hi.x() - lo.x() + 1);
  height_ = std::max(0, hi.y() - lo.y() + 1);
  origin_ = grid_origin_ + window_lo_.cast<double>().matrix() * resolution_;
  values_.assign(static_cast<std::size_t>(width_) * height_, 0.0f);
  Refill(grid, {0, 0}, {width_ - 1, height_ - 1});
}

void LikelihoodField::ApplyFlip(const OccupancyGrid& grid, const Eigen::Array2i& cell) {
  const int r = radius_cells_;
  const Eigen::Array2i w = cell - window_lo_;  // in window cells; may lie outside, within reach
  if (!(grid.LogOdds(cell) > options_.occupied_threshold)) {
    // A wall that went can lower the cells around it: recomputed from the walls now in reach.
    Refill(grid, w - r, w + r);
    return;
  }
  // A new wall only raises the cells around it.
  const int side = 2 * r + 1;
  const int dy0 = std::max(-r, -w.y()), dy1 = std::min(r, height_ - 1 - w.y());
  const int dx0 = std::max(-r, -w.x()), dx1 = std::min(r, width_ - 1 - w.x());
  if (dy0 > dy1 || dx0 > dx1) return;  // out of the window's reach
  for (int dy = dy0; dy <= dy1; ++dy) {
    float* o = values_.data() + static_cast<std::ptrdiff_t>(w.y() + dy) * width_ + w.x();
    const float* k = kernel_.data() + static_cast<std::ptrdiff_t>(dy + r) * side + r;
    for (int dx = dx0; dx <= dx1; ++dx) o[dx] = std::max(o[dx], k[dx]);
  }
}

void LikelihoodField::Follow(OccupancyGrid& grid) {
  const Eigen::Vector2d extent = Eigen::Vector2d(grid.width(), grid.height()) * grid.resolution();
  Follow(grid, Eigen::AlignedBox2d(grid.origin(), grid.origin() + extent));
}

void LikelihoodField::Follow(OccupancyGrid& grid, const Eigen::AlignedBox2d& region) {
  EnsureKernel(grid.resolution());
  const bool following = followed_ == &grid && grid.records_wall_flips() &&
                         grid.wall_threshold() == options_.occupied_threshold;
  if (!following) {
    grid.RecordWallFlips(options_.occupied_threshold);
    grid.TakeWallFlips();
    followed_ = &grid;
    Recompute(grid, region);
    return;
  }
  if (grid.origin() != grid_origin_ || grid.width() != grid_size_.x() ||
      grid.height() != grid_size_.y()) {
    // The grid grows on its own lattice: the window's old cell (0, 0) is now `shift` further.
    const Eigen::Vector2d shift_cells = (grid_origin_ - grid.origin()) / resolution_;
    window_lo_ += Eigen::Array2i(static_cast<int>(std::lround(shift_cells.x())),
                                 static_cast<int>(std::lround(shift_cells.y())));
    grid_origin_ = grid.origin();
    grid_size_ = {grid.width(), grid.height()};
    origin_ = grid_origin_ + window_lo_.cast<double>().matrix() * resolution_;
    // New cells are unknown: walls only when the threshold is below 0, and then the cells within
    // reach of them change too.
    if (options_.occupied_threshold < 0.0f) {
      grid.TakeWallFlips();
      Recompute(grid, region);
      return;
    }
  }
  for (const Eigen::Array2i& cell : grid.TakeWallFlips()) ApplyFlip(grid, cell);
  const auto [lo, hi] = GridCells(region);
  if ((lo <= hi).all() && !WindowHolds(lo, hi)) Recompute(grid, region);
}

GridView LikelihoodField::view() const {
  return GridView{values_.data(), width_, height_, origin_, resolution_};
}

GridView LikelihoodField::view(const Eigen::AlignedBox2d& region) const {
  SLAMRIG_CHECK(followed_ != nullptr, "LikelihoodField::view(region) needs Follow()");
  // The window Update(grid, region) would compute, as a view into the followed one.
  const auto [lo, hi] = GridCells(region);
  GridView view;
  view.width = std::max(0, hi.x() - lo.x() + 1);
  view.height = std::max(0, hi.y() - lo.y() + 1);
  view.origin = grid_origin_ + lo.cast<double>().matrix() * resolution_;
  view.resolution = resolution_;
  view.stride = width_;
  view.values = values_.data();
  if (view.width > 0 && view.height > 0) {
    SLAMRIG_CHECK(WindowHolds(lo, hi),
                  "LikelihoodField::view(region): the region leaves the followed window");
    view.values +=
        static_cast<std::ptrdiff_t>(lo.y() - window_lo_.y()) * width_ + (lo.x() - window_lo_.x());
  }
  return view;
}

}  // namespace slamrig::slam
