#include "slam/grid/tiled_grid.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <climits>
#include <cstdint>

#include "slam/grid/ray_trace.h"
#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// Which cells one InsertScan already changed (update_once_per_scan): a stamp per cell of the
// scan's bounding box, per thread so that particles insert in parallel. A new scan takes a new
// stamp value, so the buffer is never cleared; entries left from another box hold older stamps.
struct ScanStamps {
  std::vector<std::uint32_t> stamps;
  std::uint32_t current = 0;
  Eigen::Array2i lo = Eigen::Array2i::Zero();
  int width = 0;

  void Start(const Eigen::Array2i& box_lo, const Eigen::Array2i& box_hi) {
    lo = box_lo;
    width = box_hi.x() - box_lo.x() + 1;
    const std::size_t size =
        static_cast<std::size_t>(width) * static_cast<std::size_t>(box_hi.y() - box_lo.y() + 1);
    if (stamps.size() < size) stamps.resize(size, 0);
    if (++current == 0) {  // wrapped: old stamps could collide
      std::fill(stamps.begin(), stamps.end(), 0);
      current = 1;
    }
  }
  std::uint32_t& At(int x, int y) {
    return stamps[static_cast<std::size_t>(y - lo.y()) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x - lo.x())];
  }
};

thread_local ScanStamps scan_stamps;

}  // namespace

TiledGrid::TiledGrid(const OccupancyGridOptions& options, const Eigen::Vector2d& origin)
    : options_(options), origin_(origin) {
  SLAMRIG_CHECK_VALID(options_, "OccupancyGridOptions");
}

void TiledGrid::EnsureCells(const Eigen::Array2i& lo, const Eigen::Array2i& hi) {
  const int tx_lo = lo.x() >> kTileBits;
  const int ty_lo = lo.y() >> kTileBits;
  const int tx_hi = hi.x() >> kTileBits;
  const int ty_hi = hi.y() >> kTileBits;
  if (tiles_w_ > 0 && tx_lo >= tile_x0_ && ty_lo >= tile_y0_ && tx_hi < tile_x0_ + tiles_w_ &&
      ty_hi < tile_y0_ + tiles_h_) {
    return;
  }
  // The union of the old table and the new range; the table is small (one pointer per tile).
  const int x0 = tiles_w_ > 0 ? std::min(tile_x0_, tx_lo) : tx_lo;
  const int y0 = tiles_w_ > 0 ? std::min(tile_y0_, ty_lo) : ty_lo;
  const int x1 = tiles_w_ > 0 ? std::max(tile_x0_ + tiles_w_ - 1, tx_hi) : tx_hi;
  const int y1 = tiles_w_ > 0 ? std::max(tile_y0_ + tiles_h_ - 1, ty_hi) : ty_hi;
  const int w = x1 - x0 + 1;
  const int h = y1 - y0 + 1;
  SLAMRIG_CHECK(static_cast<double>(w) * h < 1e8, "tiled grid too large");
  std::vector<std::shared_ptr<Tile>> grown(static_cast<std::size_t>(w) * h);
  std::vector<std::shared_ptr<HitTile>> grown_hits(record_hit_means_ ? grown.size() : 0);
  for (int row = 0; row < tiles_h_; ++row) {
    for (int col = 0; col < tiles_w_; ++col) {
      const std::size_t to =
          static_cast<std::size_t>(row + tile_y0_ - y0) * w + (col + tile_x0_ - x0);
      const std::size_t from = static_cast<std::size_t>(row) * tiles_w_ + col;
      grown[to] = std::move(tiles_[from]);
      if (record_hit_means_) grown_hits[to] = std::move(hit_tiles_[from]);
    }
  }
  tiles_ = std::move(grown);
  hit_tiles_ = std::move(grown_hits);
  tile_x0_ = x0;
  tile_y0_ = y0;
  tiles_w_ = w;
  tiles_h_ = h;
}

TiledGrid::Tile& TiledGrid::MutableTile(int tx, int ty) {
  std::shared_ptr<Tile>& slot =
      tiles_[static_cast<std::size_t>(ty - tile_y0_) * tiles_w_ + (tx - tile_x0_)];
  if (!slot) {
    slot = std::make_shared<Tile>();
    slot->fill(0.0f);
  } else if (slot.use_count() > 1) {
    // Shared with another grid: this grid takes its own copy. Only grid copies raise the count and
    // they never overlap a write, so a count of 1 read here cannot be stale.
    slot = std::make_shared<Tile>(*slot);
  }
  return *slot;
}

void TiledGrid::RecordHitMeans(bool record) {
  SLAMRIG_CHECK(num_tiles() == 0, "TiledGrid::RecordHitMeans on a grid already written");
  record_hit_means_ = record;
  hit_tiles_.assign(record ? tiles_.size() : 0, nullptr);
}

TiledGrid::HitTile& TiledGrid::MutableHitTile(int tx, int ty) {
  std::shared_ptr<HitTile>& slot =
      hit_tiles_[static_cast<std::size_t>(ty - tile_y0_) * tiles_w_ + (tx - tile_x0_)];
  if (!slot) {
    slot = std::make_shared<HitTile>();
  } else if (slot.use_count() > 1) {
    slot = std::make_shared<HitTile>(*slot);  // as MutableTile: shared only by copies of grids
  }
  return *slot;
}

void TiledGrid::Update(const Eigen::Array2i& cell, float delta) {
  EnsureCells(cell, cell);
  float& l = MutableTile(cell.x() >> kTileBits, cell.y() >> kTileBits)[Offset(cell.x(), cell.y())];
  l = std::clamp(l + delta, options_.min_log_odds, options_.max_log_odds);
}

int TiledGrid::InsertScan(const LaserScan& scan, const Pose2& world_from_base,
                          std::optional<double> max_range_m) {
  const Eigen::Vector2d origin_world = (world_from_base * scan.base_from_laser).translation();
  // OccupancyGrid::InsertScan's beams.
  std::vector<std::pair<Eigen::Vector2d, bool>> ends;
  ends.reserve(scan.ranges_m.size());
  const Eigen::AlignedBox2d bounds = BeamEnds(scan, world_from_base, options_, max_range_m, &ends);
  const Eigen::Array2i lo = WorldToCell(bounds.min());
  const Eigen::Array2i hi = WorldToCell(bounds.max());
  EnsureCells(lo, hi);
  ScanStamps& stamps = scan_stamps;
  stamps.Start(lo, hi);

  // Consecutive cells of a ray mostly share a tile: remember the last one written.
  int cached_tx = INT_MIN;
  int cached_ty = INT_MIN;
  Tile* cached = nullptr;
  auto cell_at = [&](int x, int y) -> float& {
    const int tx = x >> kTileBits;
    const int ty = y >> kTileBits;
    if (tx != cached_tx || ty != cached_ty) {
      cached = &MutableTile(tx, ty);
      cached_tx = tx;
      cached_ty = ty;
    }
    return (*cached)[Offset(x, y)];
  };

  const bool once = options_.update_once_per_scan;
  const std::uint32_t now = stamps.current;
  const Eigen::Array2i start = WorldToCell(origin_world);
  int hits = 0;
  // Hits first, so that with update_once_per_scan a free ray cannot erase them.
  for (const auto& [end, hit] : ends) {
    if (!hit) continue;
    const Eigen::Array2i cell = WorldToCell(end);
    ++hits;
    if (record_hit_means_) {
      // Every hit counts, also one that update_once_per_scan keeps from the log-odds: the mean
      // is of where the wall was seen.
      HitMean& m =
          MutableHitTile(cell.x() >> kTileBits, cell.y() >> kTileBits)[Offset(cell.x(), cell.y())];
      const Eigen::Vector2d offset = end - CellCenter(cell);
      m.count += 1.0f;
      m.dx += (static_cast<float>(offset.x()) - m.dx) / m.count;
      m.dy += (static_cast<float>(offset.y()) - m.dy) / m.count;
    }
    std::uint32_t& stamp = stamps.At(cell.x(), cell.y());
    if (once && stamp == now) continue;
    stamp = now;
    float& l = cell_at(cell.x(), cell.y());
    l = std::clamp(l + options_.hit_log_odds, options_.min_log_odds, options_.max_log_odds);
  }
  for (const auto& [end, hit] : ends) {
    const Eigen::Array2i cell = WorldToCell(end);
    auto clear = [&](int x, int y) {
      if (once) {
        std::uint32_t& stamp = stamps.At(x, y);
        if (stamp == now) return;
        stamp = now;
      }
      float& l = cell_at(x, y);
      l = std::max(l + options_.miss_log_odds, options_.min_log_odds);
    };
    TraceRay(start, cell, clear);
    // A no-return beam's last cell is free too.
    if (!hit) clear(cell.x(), cell.y());
  }
  return hits;
}

int TiledGrid::num_tiles() const {
  return static_cast<int>(std::count_if(
      tiles_.begin(), tiles_.end(), [](const std::shared_ptr<Tile>& t) { return t != nullptr; }));
}

int TiledGrid::SharedTiles(const TiledGrid& other) const {
  int shared = 0;
  for (int row = 0; row < tiles_h_; ++row) {
    for (int col = 0; col < tiles_w_; ++col) {
      const Tile* mine = tiles_[static_cast<std::size_t>(row) * tiles_w_ + col].get();
      if (mine && mine == other.FindTile(col + tile_x0_, row + tile_y0_)) ++shared;
    }
  }
  return shared;
}

void TiledGrid::CollectTiles(std::vector<const Tile*>* tiles) const {
  for (const std::shared_ptr<Tile>& t : tiles_) {
    if (t) tiles->push_back(t.get());
  }
}

OccupancyGrid TiledGrid::ToOccupancyGrid() const {
  const double tile_m = kTileSize * options_.resolution_m;
  OccupancyGrid grid(options_, origin_ + Eigen::Vector2d(tile_x0_ * tile_m, tile_y0_ * tile_m),
                     tiles_w_ * kTileSize, tiles_h_ * kTileSize);
  for (int row = 0; row < tiles_h_; ++row) {
    for (int col = 0; col < tiles_w_; ++col) {
      const Tile* tile = tiles_[static_cast<std::size_t>(row) * tiles_w_ + col].get();
      if (!tile) continue;
      for (int y = 0; y < kTileSize; ++y) {
        for (int x = 0; x < kTileSize; ++x) {
          grid.Set({col * kTileSize + x, row * kTileSize + y},
                   (*tile)[static_cast<std::size_t>(y) * kTileSize + x]);
        }
      }
    }
  }
  return grid;
}

}  // namespace slamrig::slam
