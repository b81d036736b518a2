#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// A log-odds occupancy grid stored as 64 x 64-cell tiles held by shared pointers, copied on
/// first write: copying a TiledGrid copies the tile table, not the cells, so the per-particle maps
/// of a Rao-Blackwellised filter share every tile that no particle changed since they split
/// (GMapping keeps one full map per particle; Grisetti, Stachniss, Burgard, IEEE T-RO 2007,
/// Sec. VI, names sharing as the way to cut that cost). The log-odds conventions and the scan
/// update are OccupancyGrid's, cell for cell. Cell (ix, iy) covers
/// [origin.x + ix*res, origin.x + (ix+1)*res) x [origin.y + iy*res, ...); indices may be negative
/// and the grid grows without bounds; unwritten cells read as log-odds 0 (unknown).
/// Writes to different TiledGrids may run on different threads at once even when they share
/// tiles; copying a TiledGrid must not overlap a write to it.
class TiledGrid {
 public:
  static constexpr int kTileBits = 6;
  static constexpr int kTileSize = 1 << kTileBits;  ///< cells per tile side
  using Tile = std::array<float, kTileSize * kTileSize>;
  /// Where in a cell its scan end points fell: their mean as an offset from the cell's centre, and
  /// how many there were (GMapping's PointAccumulator). A matcher that measures distances to the
  /// mean, not to the centre, sees a wall where it was observed instead of on the cell lattice.
  struct HitMean {
    float dx = 0.0f;
    float dy = 0.0f;
    float count = 0.0f;
  };
  using HitTile = std::array<HitMean, kTileSize * kTileSize>;

  /// An empty grid on the lattice whose cell (0, 0) has its lower-left corner at `origin`.
  explicit TiledGrid(const OccupancyGridOptions& options,
                     const Eigen::Vector2d& origin = Eigen::Vector2d::Zero());

  const OccupancyGridOptions& options() const { return options_; }
  double resolution() const { return options_.resolution_m; }
  const Eigen::Vector2d& origin() const { return origin_; }

  /// The cell containing world point `p` (OccupancyGrid's formula, so both agree bit for bit).
  Eigen::Array2i WorldToCell(const Eigen::Vector2d& p) const {
    return {static_cast<int>(std::floor((p.x() - origin_.x()) / options_.resolution_m)),
            static_cast<int>(std::floor((p.y() - origin_.y()) / options_.resolution_m))};
  }
  /// World position of the centre of `cell`.
  Eigen::Vector2d CellCenter(const Eigen::Array2i& cell) const {
    return origin_ + (cell.cast<double>() + 0.5).matrix() * options_.resolution_m;
  }
  /// Log-odds of cell (ix, iy), 0 where nothing was written.
  float LogOdds(int ix, int iy) const {
    const Tile* tile = FindTile(ix >> kTileBits, iy >> kTileBits);
    return tile ? (*tile)[Offset(ix, iy)] : 0.0f;
  }
  float LogOdds(const Eigen::Array2i& cell) const { return LogOdds(cell.x(), cell.y()); }

  /// The tile of tile coordinates (tx, ty) = (ix >> kTileBits, iy >> kTileBits), null where
  /// nothing was written; cell (ix, iy) is its value [(iy & 63) * 64 + (ix & 63)]. For readers
  /// that visit neighbouring cells (scan matchers): one lookup, then plain indexing.
  const Tile* FindTile(int tx, int ty) const {
    const int col = tx - tile_x0_;
    const int row = ty - tile_y0_;
    if (col < 0 || row < 0 || col >= tiles_w_ || row >= tiles_h_) return nullptr;
    return tiles_[static_cast<std::size_t>(row) * tiles_w_ + col].get();
  }
  /// Makes InsertScan record every hit's position in its cell (HitMean); call it on an empty grid.
  /// Copies share these tiles as they share the log-odds ones. Off by default.
  void RecordHitMeans(bool record);
  bool records_hit_means() const { return record_hit_means_; }
  /// The hit means of tile (tx, ty), laid out as FindTile's cells; null where none was recorded.
  const HitTile* FindHitTile(int tx, int ty) const {
    const int col = tx - tile_x0_;
    const int row = ty - tile_y0_;
    if (!record_hit_means_ || col < 0 || row < 0 || col >= tiles_w_ || row >= tiles_h_) {
      return nullptr;
    }
    return hit_tiles_[static_cast<std::size_t>(row) * tiles_w_ + col].get();
  }
  /// The hit mean of cell (ix, iy); zero offset and count where none was recorded.
  HitMean HitMeanAt(int ix, int iy) const {
    const HitTile* tile = FindHitTile(ix >> kTileBits, iy >> kTileBits);
    return tile ? (*tile)[Offset(ix, iy)] : HitMean{};
  }

  /// Adds `delta` to `cell` with OccupancyGrid::Update's clamping (copying its tile if shared).
  void Update(const Eigen::Array2i& cell, float delta);

  /// OccupancyGrid::InsertScan on this grid: the same beams, cells and log-odds changes.
  /// `max_range_m`, when given, replaces the options' max_range_m for this scan (a sparse scan's
  /// SparseScanRange); the lidar's own range_max_m still bounds it.
  int InsertScan(const LaserScan& scan, const Pose2& world_from_base,
                 std::optional<double> max_range_m = std::nullopt);

  /// Tiles this grid holds (written at least once).
  int num_tiles() const;
  /// Tiles this grid holds that `other` holds too (the same storage, not equal values).
  int SharedTiles(const TiledGrid& other) const;
  /// Appends the address of every tile held, for counting distinct tiles over many grids.
  void CollectTiles(std::vector<const Tile*>* tiles) const;

  /// The grid as an OccupancyGrid covering every tile held (cell lattice kept).
  OccupancyGrid ToOccupancyGrid() const;

 private:
  static std::size_t Offset(int ix, int iy) {
    return static_cast<std::size_t>(iy & (kTileSize - 1)) * kTileSize +
           static_cast<std::size_t>(ix & (kTileSize - 1));
  }
  /// Grows the tile table to cover the cells in [lo, hi] (inclusive).
  void EnsureCells(const Eigen::Array2i& lo, const Eigen::Array2i& hi);
  /// The writable tile (tx, ty), created or unshared first; the table must cover it.
  Tile& MutableTile(int tx, int ty);
  HitTile& MutableHitTile(int tx, int ty);

  OccupancyGridOptions options_;
  Eigen::Vector2d origin_;
  int tile_x0_ = 0;
  int tile_y0_ = 0;
  int tiles_w_ = 0;
  int tiles_h_ = 0;
  std::vector<std::shared_ptr<Tile>> tiles_;  // row-major over the table, null = never written
  bool record_hit_means_ = false;
  std::vector<std::shared_ptr<HitTile>> hit_tiles_;  // as tiles_; empty unless recorded
};

}  // namespace slamrig::slam
