#include "slam/matching/occupied_mask.h"

namespace slamrig::slam {

void OccupiedMask::Reread(const OccupancyGrid& grid) {
  width_ = grid.width();
  height_ = grid.height();
  bytes_.assign(static_cast<std::size_t>(stride()) * height_, 0);
  std::vector<float> cells(static_cast<std::size_t>(width_));
  for (int y = 0; y < height_; ++y) {
    grid.CopyLogOdds({0, y}, {width_, 1}, cells.data(), 0);
    std::uint8_t* out = bytes_.data() + static_cast<std::ptrdiff_t>(y) * stride();
    for (int x = 0; x < width_; ++x) out[x] = cells[x] > threshold_ ? 1 : 0;
  }
}

void OccupiedMask::Follow(OccupancyGrid& grid) {
  const bool following =
      followed_ == &grid && grid.records_wall_flips() && grid.wall_threshold() == threshold_;
  if (!following) {
    grid.RecordWallFlips(threshold_);
    followed_ = &grid;
  }
  const std::vector<Eigen::Array2i> flips = grid.TakeWallFlips();
  // Growth is rare (the grid grows by a margin, always wider or taller): reread it whole then.
  if (!following || grid.width() != width_ || grid.height() != height_) {
    Reread(grid);
    return;
  }
  for (const Eigen::Array2i& cell : flips) {
    bytes_[static_cast<std::size_t>(cell.y()) * stride() + static_cast<std::size_t>(cell.x())] =
        grid.LogOdds(cell) > threshold_ ? 1 : 0;
  }
}

}  // namespace slamrig::slam
