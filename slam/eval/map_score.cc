#include "slam/eval/map_score.h"

#include <algorithm>
#include <cstdint>
#include <unordered_set>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

std::int64_t Key(int x, int y) {
  return (static_cast<std::int64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
}

bool HasWithin(const std::unordered_set<std::int64_t>& cells, int x, int y, int tolerance) {
  for (int dy = -tolerance; dy <= tolerance; ++dy) {
    for (int dx = -tolerance; dx <= tolerance; ++dx) {
      if (cells.count(Key(x + dx, y + dy)) > 0) return true;
    }
  }
  return false;
}

}  // namespace

std::vector<std::string> MapScoreOptions::Validate() const {
  Rules rules;
  rules.NonNegative("tolerance_cells", tolerance_cells)
      .Require(occupied_probability > 0.5 && occupied_probability < 1.0, "occupied_probability",
               occupied_probability, "must be in (0.5, 1)");
  return PrefixErrors("map_score", rules.errors());
}

MapScore ScoreMap(const OccupancyGrid& estimate, const Pose2& truth_from_estimate,
                  const OccupancyGrid& truth, const MapScoreOptions& options) {
  SLAMRIG_CHECK_VALID(options, "MapScoreOptions");
  // Occupied cells of both maps on the truth lattice (cell indices may fall outside the truth
  // grid).
  const double occupied_log_odds =
      std::log(options.occupied_probability / (1.0 - options.occupied_probability));
  std::unordered_set<std::int64_t> truth_cells, estimate_cells;
  for (int y = 0; y < truth.height(); ++y) {
    for (int x = 0; x < truth.width(); ++x) {
      if (truth.LogOdds({x, y}) > occupied_log_odds) truth_cells.insert(Key(x, y));
    }
  }
  for (int y = 0; y < estimate.height(); ++y) {
    for (int x = 0; x < estimate.width(); ++x) {
      if (!(estimate.LogOdds({x, y}) > occupied_log_odds)) continue;
      const Eigen::Array2i cell =
          truth.WorldToCell(truth_from_estimate * estimate.CellCenter({x, y}));
      estimate_cells.insert(Key(cell.x(), cell.y()));
    }
  }
  MapScore score;
  score.estimate_occupied = static_cast<int>(estimate_cells.size());
  score.truth_occupied = static_cast<int>(truth_cells.size());
  for (const std::int64_t k : estimate_cells) {
    score.estimate_matched +=
        HasWithin(truth_cells, static_cast<int>(k >> 32), static_cast<std::int32_t>(k & 0xffffffff),
                  options.tolerance_cells);
  }
  for (const std::int64_t k : truth_cells) {
    score.truth_matched +=
        HasWithin(estimate_cells, static_cast<int>(k >> 32),
                  static_cast<std::int32_t>(k & 0xffffffff), options.tolerance_cells);
  }
  if (score.estimate_occupied > 0)
    score.precision = static_cast<double>(score.estimate_matched) / score.estimate_occupied;
  if (score.truth_occupied > 0)
    score.recall = static_cast<double>(score.truth_matched) / score.truth_occupied;
  if (score.precision + score.recall > 0.0) {
    score.f1 = 2.0 * score.precision * score.recall / (score.precision + score.recall);
  }
  score.iou = score.f1 / (2.0 - score.f1);
  return score;
}

}  // namespace slamrig::slam
