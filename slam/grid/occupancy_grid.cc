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
  origin_ = origin;
  width_ = width;
  height_ = height;
  log_odds_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0f);
  last_update_.assign(log_odds_.size(), 0);
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

  std::vector<float> grown(static_cast<std::size_t>(new_width) * new_height, 0.0f);
  std::vector<std::uint32_t> grown_updates(grown.size(), 0);
  const int shift_x = static_cast<int>(-lo_cells.x());
  const int shift_y = static_cast<int>(-lo_cells.y());
  for (int iy = 0; iy < height_; ++iy) {
    const std::size_t dst = static_cast<std::size_t>(iy + shift_y) * new_width + shift_x;
    std::copy_n(log_odds_.begin() + static_cast<std::ptrdiff_t>(Index(0, iy)), width_,
                grown.begin() + static_cast<std::ptrdiff_t>(dst));
    std::copy_n(last_update_.begin() + static_cast<std::ptrdiff_t>(Index(0, iy)), width_,
                grown_updates.begin() + static_cast<std::ptrdiff_t>(dst));
  }
  log_odds_ = std::move(grown);
  last_update_ = std::move(grown_updates);
  for (Eigen::Array2i& cell : flips_) cell += Eigen::Array2i(shift_x, shift_y);
  origin_ = new_origin;
  width_ = new_width;
  height_ = new_height;
}

void OccupancyGrid::RecordWallFlips(float threshold) {
  SLAMRIG_CHECK(!records_flips_ || threshold == wall_threshold_,
                "a grid records wall flips for one threshold");
  records_flips_ = true;
  wall_threshold_ = threshold;
}

void OccupancyGrid::RecordFlip(std::size_t index) {
  flips_.push_back({static_cast<int>(index % static_cast<std::size_t>(width_)),
                    static_cast<int>(index / static_cast<std::size_t>(width_))});
}

std::vector<Eigen::Array2i> OccupancyGrid::TakeWallFlips() {
  std::vector<Eigen::Array2i> taken;
  taken.swap(flips_);
  return taken;
}

int OccupancyGrid::InsertScan(const LaserScan& scan, const Pose2& world_from_base) {
  const Pose2 world_from_laser = world_from_base * scan.base_from_laser;
  const Eigen::Vector2d origin_world = world_from_laser.translation();
  const double max_hit_range = std::min(scan.range_max_m, options_.max_range_m);
  const double clear_range = std::min(max_hit_range, options_.no_return_clear_range_m);

  // Beam end points in the world, and which of them are hits.
  Eigen::AlignedBox2d bounds(origin_world, origin_world);
  std::vector<std::pair<Eigen::Vector2d, bool>>& ends = beam_ends_;
  ends.clear();
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const double r = scan.ranges_m[i];
    if (!(r >= scan.range_min_m)) continue;  // too short: no information
    const bool hit = r < max_hit_range;
    const double length = hit ? r : clear_range;
    if (length <= 0.0) continue;
    const double angle = world_from_laser.theta() + scan.BeamAngle(i);
    const Eigen::Vector2d end =
        origin_world + length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    if (!end.allFinite()) continue;  // sources reject NaN; never index with one
    bounds.extend(end);
    ends.emplace_back(end, hit);
  }
  EnsureContains(bounds);

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
    std::uint32_t& stamp = last_update_[Index(cell.x(), cell.y())];
    if (once && stamp == scan_count_) continue;
    stamp = scan_count_;
    const std::size_t index = Index(cell.x(), cell.y());
    Assign(index, std::clamp(log_odds_[index] + options_.hit_log_odds, options_.min_log_odds,
                             options_.max_log_odds));
  }
  for (std::size_t j = 0; j < ends.size(); ++j) {
    const bool hit = ends[j].second;
    const Eigen::Array2i cell = cells[j];
    TraceRay(start, cell, [&](int x, int y) {
      const std::size_t index = Index(x, y);
      if (once) {
        if (last_update_[index] == scan_count_) return;
        last_update_[index] = scan_count_;
      }
      Assign(index, std::max(log_odds_[index] + options_.miss_log_odds, options_.min_log_odds));
    });
    // A no-return beam's last cell is free too.
    if (!hit) {
      const std::size_t index = Index(cell.x(), cell.y());
      if (!once || last_update_[index] != scan_count_) {
        last_update_[index] = scan_count_;
        Assign(index, std::max(log_odds_[index] + options_.miss_log_odds, options_.min_log_odds));
      }
    }
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
