#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// How scans change the log-odds grid. A hit is trusted at 80 % as in the ECE276A reports
/// (+log 4); a pass-through counts as p = 0.4 (-0.405), weaker than the hit so that a wall seen
/// once survives the grazing rays of later scans (the reports' asymmetric-update lesson).
/// On intel-corrected this keeps F1 >= 0.92 against a raw end-point raster and >= 0.96
/// against the reports' symmetric +-log 4 grid (tests/intel_map_test.cc).
struct OccupancyGridOptions {
  double resolution_m = 0.05;             ///< cell edge length
  float hit_log_odds = 1.3862944f;        ///< added to a beam's end cell, log(4)
  float miss_log_odds = -0.4054651f;      ///< added to cells a beam passes, log(0.4/0.6)
  float min_log_odds = -5.0f;             ///< clamp (keeps the map able to change)
  float max_log_odds = 5.0f;              ///< clamp
  double max_range_m = 30.0;              ///< longer returns are treated as no return
  double no_return_clear_range_m = 10.0;  ///< free space cleared along a no-return beam
  /// Update each cell at most once per scan, hits first (Cartographer's rule): a wall cell grazed
  /// by a neighbouring beam's free ray in the same scan stays a wall. false: every beam counts, as
  /// in the reports.
  bool update_once_per_scan = true;
  double grow_margin_m = 5.0;  ///< extra room added when the map grows
  /// Standard deviation of the ranges (the lidar's noise); 0: every hit marks its end cell. Else a
  /// hit marks the cell of most wall evidence (log-odds > 0) on its ray within hit_window_sigmas
  /// of it before the end point, or the end cell, and its free ray stops there: the beam cannot
  /// have passed a wall, an end point behind one lies there by noise. Why: a hit that noise puts
  /// behind a wall marks a cell no later beam can clear (the wall stops them all), while one put in
  /// front is cleared by the free rays of later beams, so each wall grows a fringe behind its
  /// surface, its cells' centroid about one sigma behind it (slam/grid/wall_bias_test.cc), and
  /// scans matched to them drift towards the walls (the office pf's corridors 1-2.6 cm too wide,
  /// issue 11).
  double range_stddev_m = 0.0;
  double hit_window_sigmas = 2.5;  ///< the window before a hit searched for a wall, in sigmas

  /// One message per broken rule, e.g. "resolution_m = 0; must be > 0".
  std::vector<std::string> Validate() const;
};

/// The field table of OccupancyGridOptions (slam/config/fields.h): YAML keys as the names.
template <typename V>
void VisitFields(V& v, OccupancyGridOptions& o) {
  v("resolution_m", o.resolution_m);
  v("hit_log_odds", o.hit_log_odds);
  v("miss_log_odds", o.miss_log_odds);
  v("min_log_odds", o.min_log_odds);
  v("max_log_odds", o.max_log_odds);
  v("max_range_m", o.max_range_m);
  v("no_return_clear_range_m", o.no_return_clear_range_m);
  v("update_once_per_scan", o.update_once_per_scan);
  v("grow_margin_m", o.grow_margin_m);
  v("range_stddev_m", o.range_stddev_m);
  v("hit_window_sigmas", o.hit_window_sigmas);
}

/// Occupancy state of a cell after thresholding its probability.
enum class CellState : std::int8_t { kUnknown = -1, kFree = 0, kOccupied = 100 };

/// The world end points of `scan`'s beams seen from `world_from_base`, and which are hits, in
/// beam order into `ends` (cleared first): a return shorter than the hit range (`max_range_m` when
/// given, else `options.max_range_m`, within the lidar's range_max_m) ends at its range, any other
/// beam at the clear range (no_return_clear_range_m, within the hit range); beams below the scan's
/// minimum range, of no length, or not finite are left out. A sweeping scan's beam ends where the
/// base was at the beam's time (the ray still starts at the laser at the scan's time: the base
/// moves centimetres in a sweep). Returns the box around the laser and every end.
/// OccupancyGrid's and TiledGrid's InsertScan both start from it.
Eigen::AlignedBox2d BeamEnds(const LaserScan& scan, const Pose2& world_from_base,
                             const OccupancyGridOptions& options, std::optional<double> max_range_m,
                             std::vector<std::pair<Eigen::Vector2d, bool>>* ends);

/// A 2D log-odds occupancy grid (Thrun, Burgard, Fox, "Probabilistic Robotics", Table 9.1)
/// that grows to fit the data. Cell (ix, iy) covers
/// [origin.x + ix*res, origin.x + (ix+1)*res) x [origin.y + iy*res, ...), 0 <= ix < width(),
/// 0 <= iy < height(); cells outside the grid read as log-odds 0 (unknown).
/// Storage is tiles of 64 x 64 cells, allocated when a cell in them is first written: the
/// bounding box (width() x height()) may grow to hundreds of metres while memory and the cost of
/// growing follow the ground the scans covered (a dense array was copied whole at every growth:
/// docs/studies/large-maps.md). Readers take cells one by one (LogOdds) or a window as a dense
/// raster (CopyLogOdds).
class OccupancyGrid {
 public:
  /// An empty grid; it takes its size from the first scan.
  explicit OccupancyGrid(const OccupancyGridOptions& options);
  /// A grid of `width` x `height` unknown cells whose cell (0, 0) has its lower-left corner at
  /// `origin` (loading a map); it still grows when data falls outside.
  OccupancyGrid(const OccupancyGridOptions& options, const Eigen::Vector2d& origin, int width,
                int height);

  const OccupancyGridOptions& options() const { return options_; }
  double resolution() const { return options_.resolution_m; }
  /// World position of the lower-left corner of cell (0, 0).
  const Eigen::Vector2d& origin() const { return origin_; }
  int width() const { return width_; }
  int height() const { return height_; }
  /// Copies the log-odds of the `size.x()` x `size.y()` cells from `lo` into `out`, row-major with
  /// rows `stride` floats apart; cells outside the grid or never written read 0. Costs the
  /// window's area, whatever the grid's size.
  void CopyLogOdds(const Eigen::Array2i& lo, const Eigen::Array2i& size, float* out,
                   std::ptrdiff_t stride) const;
  /// The whole grid's log-odds, row-major, width() * height() values (row 0 at the lowest y).
  /// Costs the bounding box: for outputs and tests, not for per-scan work.
  std::vector<float> DenseLogOdds() const;
  /// The smallest box of cells whose log-odds is not 0 (empty when none): what the scans observed
  /// of the bounding box, found tile by tile.
  Eigen::AlignedBox2i ObservedCells() const;
  /// Tiles allocated (written at least once); each costs kTileBytes.
  int num_tiles() const { return static_cast<int>(tiles_.size()); }

  /// The cell containing world point `p` (may be outside the grid).
  Eigen::Array2i WorldToCell(const Eigen::Vector2d& p) const {
    return {static_cast<int>(std::floor((p.x() - origin_.x()) / options_.resolution_m)),
            static_cast<int>(std::floor((p.y() - origin_.y()) / options_.resolution_m))};
  }
  /// World position of the centre of `cell`.
  Eigen::Vector2d CellCenter(const Eigen::Array2i& cell) const {
    return origin_ + (cell.cast<double>() + 0.5).matrix() * options_.resolution_m;
  }
  bool Contains(const Eigen::Array2i& cell) const {
    return cell.x() >= 0 && cell.y() >= 0 && cell.x() < width_ && cell.y() < height_;
  }
  /// The cells [lo, hi] (inclusive) of the grid that world box `region` overlaps, clipped to the
  /// grid; empty when some coordinate of hi is below lo's.
  std::pair<Eigen::Array2i, Eigen::Array2i> CellsIn(const Eigen::AlignedBox2d& region) const {
    return {WorldToCell(region.min()).max(Eigen::Array2i(0, 0)),
            WorldToCell(region.max()).min(Eigen::Array2i(width_ - 1, height_ - 1))};
  }
  /// Log-odds of `cell`, 0 outside the grid.
  float LogOdds(const Eigen::Array2i& cell) const {
    if (!Contains(cell)) return 0.0f;
    const Tile* tile = FindTile(cell.x(), cell.y());
    return tile != nullptr ? tile->log_odds[Offset(cell.x(), cell.y())] : 0.0f;
  }
  /// Occupancy probability of `cell`, 0.5 outside the grid.
  double Probability(const Eigen::Array2i& cell) const {
    return 1.0 - 1.0 / (1.0 + std::exp(static_cast<double>(LogOdds(cell))));
  }
  /// ROS map_server style thresholding: occupied above `occupied_probability`, free below
  /// `free_probability`, unknown in between or never observed.
  CellState State(const Eigen::Array2i& cell, double occupied_probability = 0.65,
                  double free_probability = 0.196) const;

  /// Grows the grid (keeping its contents and cell alignment) so that `box` lies inside it.
  void EnsureContains(const Eigen::AlignedBox2d& box);

  /// Inserts one scan taken at `world_from_base`: each hit's end cell gains hit_log_odds and the
  /// cells before it lose miss_log_odds; a no-return beam only clears free space, up to
  /// no_return_clear_range_m. Returns the number of beams that produced a hit.
  /// `max_range_m`, when given, replaces the options' max_range_m for this scan (a sparse scan's
  /// SparseScanRange); the lidar's own range_max_m still bounds it.
  int InsertScan(const LaserScan& scan, const Pose2& world_from_base,
                 std::optional<double> max_range_m = std::nullopt);

  /// Adds `delta` to `cell` with clamping; the grid must contain the cell.
  void Update(const Eigen::Array2i& cell, float delta) {
    float& l = MutableTile(cell.x(), cell.y()).log_odds[Offset(cell.x(), cell.y())];
    Assign(cell.x(), cell.y(), l,
           std::clamp(l + delta, options_.min_log_odds, options_.max_log_odds));
  }
  /// Sets `cell` to `value` unclamped (map loading); the grid must contain the cell.
  void Set(const Eigen::Array2i& cell, float value);

  /// From now on, records every cell whose wall state (log-odds > `threshold`) flips, so that a
  /// raster derived from the walls (LikelihoodField::Follow) can be redone only where they
  /// changed. Recording stays on; a second call must give the same threshold.
  void RecordWallFlips(float threshold);
  bool records_wall_flips() const { return records_flips_; }
  float wall_threshold() const { return wall_threshold_; }
  /// The cells whose wall state flipped since the last call, on the current lattice (re-based when
  /// the grid grew); a cell may appear more than once. Clears the record: one reader per grid.
  std::vector<Eigen::Array2i> TakeWallFlips();

 private:
  static constexpr int kTileBits = 6;
  static constexpr int kTileSize = 1 << kTileBits;
  // A tile's cells, row-major, and the scan number that last touched each (update_once_per_scan).
  struct Tile {
    float log_odds[kTileSize * kTileSize] = {};
    std::uint32_t stamps[kTileSize * kTileSize] = {};
  };

 public:
  static constexpr std::size_t kTileBytes = sizeof(Tile);

 private:
  // Tiles sit on a lattice fixed at the first origin: grid cell (ix, iy) is lattice cell
  // (ix, iy) + shift_, so growing the grid down or left re-indexes the table, never the tiles.
  int TableIndex(int ix, int iy) const {
    const int tx = ((ix + shift_.x()) >> kTileBits) - table_lo_.x();
    const int ty = ((iy + shift_.y()) >> kTileBits) - table_lo_.y();
    return ty * table_size_.x() + tx;
  }
  std::size_t Offset(int ix, int iy) const {
    return static_cast<std::size_t>((iy + shift_.y()) & (kTileSize - 1)) * kTileSize +
           static_cast<std::size_t>((ix + shift_.x()) & (kTileSize - 1));
  }
  // The tile of grid cell (ix, iy), which the grid contains; null if never written.
  const Tile* FindTile(int ix, int iy) const {
    const std::int32_t t = table_[static_cast<std::size_t>(TableIndex(ix, iy))];
    return t >= 0 ? &tiles_[static_cast<std::size_t>(t)] : nullptr;
  }
  // The tile of grid cell (ix, iy), which the grid contains, allocated if need be.
  Tile& MutableTile(int ix, int iy) {
    std::int32_t& t = table_[static_cast<std::size_t>(TableIndex(ix, iy))];
    if (t < 0) [[unlikely]]
      t = AllocateTile();
    return tiles_[static_cast<std::size_t>(t)];
  }
  std::int32_t AllocateTile();
  // Resizes the table to cover the grid's bounding box.
  void CoverBoundingBox();

  // Stores `value` into `l`, the log-odds of cell (ix, iy), recording a wall flip.
  void Assign(int ix, int iy, float& l, float value) {
    if (records_flips_ && (l > wall_threshold_) != (value > wall_threshold_)) [[unlikely]] {
      flips_.push_back({ix, iy});
    }
    l = value;
  }

  OccupancyGridOptions options_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  int width_ = 0;
  int height_ = 0;
  Eigen::Array2i shift_ = Eigen::Array2i::Zero();
  // The table: one entry per tile of the bounding box, the tile's index in tiles_ or -1.
  Eigen::Array2i table_lo_ = Eigen::Array2i::Zero();
  Eigen::Array2i table_size_ = Eigen::Array2i::Zero();
  std::vector<std::int32_t> table_;
  std::deque<Tile> tiles_;  // a deque: growing never moves a tile
  std::uint32_t scan_count_ = 0;
  // Wall flips since the last TakeWallFlips, when recording.
  bool records_flips_ = false;
  float wall_threshold_ = 0.0f;
  std::vector<Eigen::Array2i> flips_;
  // The cell a hit from `origin` ending at `end` marks (see range_stddev_m).
  Eigen::Array2i HitCell(const Eigen::Vector2d& origin, const Eigen::Vector2d& end) const;

  // Scratch buffers reused across scans: beam end points and whether each is a hit; the cell each
  // marks or stops at.
  std::vector<std::pair<Eigen::Vector2d, bool>> beam_ends_;
  std::vector<Eigen::Array2i> end_cells_;
};

}  // namespace slamrig::slam
