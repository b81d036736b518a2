#pragma once

#include <cstdint>
#include <vector>

#include "slam/grid/occupancy_grid.h"

namespace slamrig::slam {

/// The walls of an OccupancyGrid (log-odds > threshold) as one byte per cell (1 = wall) on the
/// grid's lattice, kept up to date from the grid's wall flips (as LikelihoodField::Follow). The
/// occupied-indicator correlation (MapCorrelator) adds 16 cells per SIMD byte add from it, where
/// the float log-odds need three loads, compares and masks, and counts in integers, which give
/// the same float sums exactly.
class OccupiedMask {
 public:
  /// Bytes readable past a row's last cell.
  static constexpr int kRowPadding = 32;

  explicit OccupiedMask(float threshold) : threshold_(threshold) {}

  /// Brings the mask up to date with `grid`: the first call (or another grid) reads it whole and
  /// starts its wall-flip record; later calls set the flipped cells only (and reread the grid when
  /// it grew). One follower per grid (it takes the flips).
  void Follow(OccupancyGrid& grid);

  float threshold() const { return threshold_; }
  int width() const { return width_; }
  int height() const { return height_; }
  /// Bytes from one row to the next (width + kRowPadding).
  int stride() const { return width_ + kRowPadding; }
  /// Cell (0, 0); row-major, rows stride() bytes apart, 1 for a wall, 0 otherwise.
  const std::uint8_t* data() const { return bytes_.data(); }
  /// Whether cell (x, y) (inside the lattice) is a wall.
  bool Get(int x, int y) const {
    return bytes_[static_cast<std::size_t>(y) * stride() + static_cast<std::size_t>(x)] != 0;
  }

 private:
  void Reread(const OccupancyGrid& grid);

  float threshold_;
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> bytes_;
  const OccupancyGrid* followed_ = nullptr;
};

}  // namespace slamrig::slam
