#include "slam/grid/occupancy_grid.h"

#include "slam/grid/ray_trace.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> OccupancyGridOptions::Validate() const {
  Rules rules;
  rules.Positive("resolution_m", resolution_m)
      .Positive("hit_log_odds", hit_log_odds)
      .Require(miss_log_odds < 0.0f, "miss_log_odds", miss_log_odds, "must be < 0")
      .Require(min_log_odds < 0.0f, "min_log_odds", min_log_odds, "must be < 0")
      .Positive("max_log_odds", max_log_odds)
      .Positive("max_range_m", max_range_m)
      .NonNegative("no_return_clear_range_m", no_return_clear_range_m)
      .NonNegative("grow_margin_m", grow_margin_m)
      .NonNegative("range_stddev_m", range_stddev_m)
      .NonNegative("hit_window_sigmas", hit_window_sigmas);
  return rules.errors();
}

OccupancyGrid::OccupancyGrid(const OccupancyGridOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "OccupancyGridOptions");
}

OccupancyGrid::OccupancyGrid(const OccupancyGridOptions& options, const Eigen::Vector2d& origin,
                             int width, int height)
    : OccupancyGrid(options) {
  SLAMRIG_CHECK(width >= 0 && height >= 0, "grid size must not be negative");
  SLAMRIG_CHECK(static_cast<double>(width) * height < 2e9, "occupancy grid too large");
  origin_ = origin;
  width_ = width;
  height_ = height;
  CoverBoundingBox();
}

CellState OccupancyGrid::State(const Eigen::Array2i& cell, double occupied_probability,
                               double free_probability) const {
  const float l = LogOdds(cell);
  if (l == 0.0f) return CellState::kUnknown;
  const double p = Probability(cell);
  if (p > occupied_probability) return CellState::kOccupied;
  if (p < free_probability) return CellState::kFree;
  return CellState::kUnknown;
}

void OccupancyGrid::Set(const Eigen::Array2i& cell, float value) {
  // Setting an unwritten cell to unknown needs no tile (loading a map sets every cell).
  if (value == 0.0f && FindTile(cell.x(), cell.y()) == nullptr) return;
  Assign(cell.x(), cell.y(), MutableTile(cell.x(), cell.y()).log_odds[Offset(cell.x(), cell.y())],
         value);
}

std::int32_t OccupancyGrid::AllocateTile() {
  SLAMRIG_CHECK(tiles_.size() < static_cast<std::size_t>(INT32_MAX), "occupancy grid too large");
  tiles_.emplace_back();
  return static_cast<std::int32_t>(tiles_.size() - 1);
}

void OccupancyGrid::CoverBoundingBox() {
  if (width_ <= 0 || height_ <= 0) return;
  const Eigen::Array2i lo(shift_.x() >> kTileBits, shift_.y() >> kTileBits);
  const Eigen::Array2i hi((width_ - 1 + shift_.x()) >> kTileBits,
                          (height_ - 1 + shift_.y()) >> kTileBits);
  const Eigen::Array2i size = hi - lo + 1;
  // The grid only grows: every old tile has a place in the new table.
  std::vector<std::int32_t> table(static_cast<std::size_t>(size.x()) * size.y(), -1);
  for (int row = 0; row < table_size_.y(); ++row) {
    for (int col = 0; col < table_size_.x(); ++col) {
      const Eigen::Array2i to = table_lo_ + Eigen::Array2i(col, row) - lo;
      table[static_cast<std::size_t>(to.y()) * size.x() + to.x()] =
          table_[static_cast<std::size_t>(row) * table_size_.x() + col];
    }
  }
  table_ = std::move(table);
  table_lo_ = lo;
  table_size_ = size;
}

void OccupancyGrid::EnsureContains(const Eigen::AlignedBox2d& box) {
  if (box.isEmpty()) return;
  const double res = options_.resolution_m;
  if (width_ > 0) {
    const Eigen::Array2i lo = WorldToCell(box.min());
    const Eigen::Array2i hi = WorldToCell(box.max());
    if (Contains(lo) && Contains(hi)) return;
  }
  // New bounds: union of the old grid and the box, plus a margin, snapped to the old cell lattice.
  Eigen::AlignedBox2d wanted = box;
  if (width_ > 0) {
    wanted.extend(origin_);
    wanted.extend(origin_ + Eigen::Vector2d(width_ * res, height_ * res));
  }
  const Eigen::Vector2d margin = Eigen::Vector2d::Constant(options_.grow_margin_m + res);
  const Eigen::Vector2d anchor = width_ > 0 ? origin_ : Eigen::Vector2d::Zero();
  const Eigen::Vector2d lo_cells = ((wanted.min() - margin - anchor) / res).array().floor();
  const Eigen::Vector2d hi_cells = ((wanted.max() + margin - anchor) / res).array().ceil();
  const Eigen::Vector2d new_origin = anchor + lo_cells * res;
  const int new_width = static_cast<int>(hi_cells.x() - lo_cells.x());
  const int new_height = static_cast<int>(hi_cells.y() - lo_cells.y());
  SLAMRIG_CHECK(static_cast<double>(new_width) * new_height < 2e9, "occupancy grid too large");

  // Old cell (ix, iy) is new cell (ix, iy) + shift; the tiles stay where they are on the lattice.
  const Eigen::Array2i shift(static_cast<int>(-lo_cells.x()), static_cast<int>(-lo_cells.y()));
  if (width_ > 0) shift_ -= shift;
  for (Eigen::Array2i& cell : flips_) cell += shift;
  origin_ = new_origin;
  width_ = new_width;
  height_ = new_height;
  CoverBoundingBox();
}

void OccupancyGrid::CopyLogOdds(const Eigen::Array2i& lo, const Eigen::Array2i& size, float* out,
                                std::ptrdiff_t stride) const {
  for (int row = 0; row < size.y(); ++row) {
    float* dst = out + static_cast<std::ptrdiff_t>(row) * stride;
    const int y = lo.y() + row;
    if (y < 0 || y >= height_) {
      std::fill_n(dst, size.x(), 0.0f);
      continue;
    }
    int x = lo.x();
    const int end = lo.x() + size.x();
    while (x < end) {
      if (x < 0 || x >= width_) {  // outside the grid, up to its edge or the window's end
        const int stop = x < 0 ? std::min(end, 0) : end;
        std::fill_n(dst + (x - lo.x()), stop - x, 0.0f);
        x = stop;
        continue;
      }
      // Up to the end of this tile's row, the grid or the window.
      const int in_tile = kTileSize - ((x + shift_.x()) & (kTileSize - 1));
      const int stop = std::min({end, width_, x + in_tile});
      const Tile* tile = FindTile(x, y);
      if (tile != nullptr) {
        std::copy_n(tile->log_odds + Offset(x, y), stop - x, dst + (x - lo.x()));
      } else {
        std::fill_n(dst + (x - lo.x()), stop - x, 0.0f);
      }
      x = stop;
    }
  }
}

std::vector<float> OccupancyGrid::DenseLogOdds() const {
  std::vector<float> values(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  CopyLogOdds({0, 0}, {width_, height_}, values.data(), width_);
  return values;
}

Eigen::AlignedBox2i OccupancyGrid::ObservedCells() const {
  Eigen::AlignedBox2i box;  // empty
  for (int row = 0; row < table_size_.y(); ++row) {
    for (int col = 0; col < table_size_.x(); ++col) {
      const std::int32_t t = table_[static_cast<std::size_t>(row) * table_size_.x() + col];
      if (t < 0) continue;
      const Tile& tile = tiles_[static_cast<std::size_t>(t)];
      // Grid cell of the tile's cell (0, 0).
      const Eigen::Array2i corner = (table_lo_ + Eigen::Array2i(col, row)) * kTileSize - shift_;
      for (int cy = 0; cy < kTileSize; ++cy) {
        for (int cx = 0; cx < kTileSize; ++cx) {
          if (tile.log_odds[cy * kTileSize + cx] == 0.0f) continue;
          box.extend(Eigen::Vector2i(corner.x() + cx, corner.y() + cy));
        }
      }
    }
  }
  return box;
}

void OccupancyGrid::RecordWallFlips(float threshold) {
  SLAMRIG_CHECK(!records_flips_ || threshold == wall_threshold_,
                "a grid records wall flips for one threshold");
  records_flips_ = true;
  wall_threshold_ = threshold;
}

std::vector<Eigen::Array2i> OccupancyGrid::TakeWallFlips() {
  std::vector<Eigen::Array2i> taken;
  taken.swap(flips_);
  return taken;
}

Eigen::AlignedBox2d BeamEnds(const LaserScan& scan, const Pose2& world_from_base,
                             const OccupancyGridOptions& options, std::optional<double> max_range_m,
                             std::vector<std::pair<Eigen::Vector2d, bool>>* ends) {
  const double max_hit_range =
      std::min(scan.range_max_m, max_range_m.value_or(options.max_range_m));
  const double clear_range = std::min(max_hit_range, options.no_return_clear_range_m);
  const Pose2 world_from_laser = world_from_base * scan.base_from_laser;
  const Eigen::Vector2d origin_world = world_from_laser.translation();
  const bool sweeps = scan.Sweeps();
  const Pose2 base_from_world = world_from_base.Inverse();
  Eigen::AlignedBox2d bounds(origin_world, origin_world);
  ends->clear();
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const double r = scan.ranges_m[i];
    if (!(r >= scan.range_min_m)) continue;  // too short: no information
    const bool hit = r < max_hit_range;
    const double length = hit ? r : clear_range;
    if (length <= 0.0) continue;
    const double angle = world_from_laser.theta() + scan.BeamAngle(i);
    Eigen::Vector2d end = origin_world + length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    if (sweeps) end = world_from_base * (scan.SweepPose(i) * (base_from_world * end));
    if (!end.allFinite()) continue;  // sources reject NaN; never index with one
    bounds.extend(end);
    ends->emplace_back(end, hit);
  }
  return bounds;
}

int OccupancyGrid::InsertScan(const LaserScan& scan, const Pose2& world_from_base,
                              std::optional<double> max_range_m) {
  const Eigen::Vector2d origin_world = (world_from_base * scan.base_from_laser).translation();
  std::vector<std::pair<Eigen::Vector2d, bool>>& ends = beam_ends_;
  EnsureContains(BeamEnds(scan, world_from_base, options_, max_range_m, &ends));

  ++scan_count_;
  const bool once = options_.update_once_per_scan;
  const Eigen::Array2i start = WorldToCell(origin_world);
  int hits = 0;
  // Hits first, so that with update_once_per_scan a free ray cannot erase them.
  std::vector<Eigen::Array2i>& cells = end_cells_;
  cells.resize(ends.size());
  for (std::size_t j = 0; j < ends.size(); ++j) {
    const auto& [end, hit] = ends[j];
    cells[j] = hit ? HitCell(origin_world, end) : WorldToCell(end);
    if (!hit) continue;
    const Eigen::Array2i cell = cells[j];
    ++hits;
    Tile& tile = MutableTile(cell.x(), cell.y());
    const std::size_t offset = Offset(cell.x(), cell.y());
    std::uint32_t& stamp = tile.stamps[offset];
    if (once && stamp == scan_count_) continue;
    stamp = scan_count_;
    float& l = tile.log_odds[offset];
    Assign(cell.x(), cell.y(), l,
           std::clamp(l + options_.hit_log_odds, options_.min_log_odds, options_.max_log_odds));
  }
  for (std::size_t j = 0; j < ends.size(); ++j) {
    const bool hit = ends[j].second;
    const Eigen::Array2i cell = cells[j];
    auto clear = [&](int x, int y) {
      Tile& tile = MutableTile(x, y);
      const std::size_t offset = Offset(x, y);
      if (once) {
        if (tile.stamps[offset] == scan_count_) return;
        tile.stamps[offset] = scan_count_;
      }
      float& l = tile.log_odds[offset];
      Assign(x, y, l, std::max(l + options_.miss_log_odds, options_.min_log_odds));
    };
    TraceRay(start, cell, clear);
    // A no-return beam's last cell is free too.
    if (!hit) clear(cell.x(), cell.y());
  }
  return hits;
}

Eigen::Array2i OccupancyGrid::HitCell(const Eigen::Vector2d& origin,
                                      const Eigen::Vector2d& end) const {
  const Eigen::Array2i end_cell = WorldToCell(end);
  const double window = options_.range_stddev_m * options_.hit_window_sigmas;
  if (!(window > 0.0)) return end_cell;
  const Eigen::Vector2d ray = end - origin;
  const double length = ray.norm();
  if (!(length > 0.0)) return end_cell;
  // Samples at most half a cell apart from the window's start to the end point. The cell with the
  // most wall evidence wins, so a fringe cell that noise marked once does not take the hits of the
  // wall behind it; on a tie (cells at the clamp) the one nearest the end point, so a hit stays
  // where it fell unless a stronger wall stands before it. Ties to the sensor side let a saturated
  // fringe cell in front take the wall's hits: on 5 cm cells the walls then sat 0.45 sigma in
  // front of the surface.
  const double reach = std::min(window, length);
  const int samples = static_cast<int>(std::ceil(reach / (0.5 * options_.resolution_m)));
  const double step = reach / samples;
  Eigen::Array2i best = end_cell;
  float best_log_odds = 0.0f;
  for (int k = samples; k >= 0; --k) {
    const Eigen::Array2i cell = k == 0 ? end_cell : WorldToCell(end - (k * step / length) * ray);
    const float l = LogOdds(cell);
    if (l >= best_log_odds && l > 0.0f) {
      best = cell;
      best_log_odds = l;
    }
  }
  return best;
}

}  // namespace slamrig::slam
