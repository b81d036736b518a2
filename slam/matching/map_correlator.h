#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "slam/matching/grid_view.h"
#include "slam/matching/occupied_mask.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// What a map cell contributes to the correlation when a scan point lands in it.
enum class CorrelationValue {
  /// 1 if the cell's value is above `occupied_threshold`, else 0: the reports' mapCorrelation on
  /// the thresholded map (Wang, ECE276A report, Sec. II-D).
  kOccupiedIndicator,
  /// The cell's value itself: log-odds (Zafari's variant) or a likelihood-field raster.
  kRawValue,
};

/// The shift search of the map-correlation observation model.
struct MapCorrelatorOptions {
  /// Shifts of -n..n cells in x and y around the pose: 4 gives the reports' 9x9 grid.
  int xy_half_width_cells = 4;
  /// Yaw shifts of -n..n steps of `yaw_step_rad` (Wang's extra shift in yaw); 0 = none.
  int yaw_half_steps = 0;
  double yaw_step_rad = 0.005;
  CorrelationValue value = CorrelationValue::kOccupiedIndicator;
  float occupied_threshold = 0.0f;  ///< for kOccupiedIndicator: log-odds above this is a wall

  /// Motion prior over the window (Olson, "Real-Time Correlative Scan Matching", ICRA 2009,
  /// Sec. III: the scan likelihood times the odometry prior): a shift (dx, dy, dyaw) is ranked by
  /// score - 0.5 (|(dx, dy)| / prior_sigma_xy_m)^2 - 0.5 (dyaw / prior_sigma_yaw_rad)^2, in score
  /// units. Where the score is flat (a corridor, along its axis) the centre wins instead of a
  /// noisy near-tie. 0 = no prior on that part (the reports).
  double prior_sigma_xy_m = 0.0;
  double prior_sigma_yaw_rad = 0.0;
  /// Leave the pose unshifted unless the best shift's ranked value beats the centre's score by more
  /// than this (score units). 0 = any gain moves it.
  float min_shift_gain = 0.0f;

  /// Side of the xy shift grid, 2n + 1.
  int side() const { return 2 * xy_half_width_cells + 1; }
  /// Number of yaw shifts, 2n + 1.
  int num_yaws() const { return 2 * yaw_half_steps + 1; }
  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of MapCorrelatorOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, MapCorrelatorOptions& o) {
  v("xy_half_width_cells", o.xy_half_width_cells);
  v("yaw_half_steps", o.yaw_half_steps);
  v("yaw_step_rad", o.yaw_step_rad);
  v.Enum("value", o.value,
         {{CorrelationValue::kOccupiedIndicator, "occupied"},
          {CorrelationValue::kRawValue, "log_odds"}});
  v("occupied_threshold", o.occupied_threshold);
  v("prior_sigma_xy_m", o.prior_sigma_xy_m);
  v("prior_sigma_yaw_rad", o.prior_sigma_yaw_rad);
  v("min_shift_gain", o.min_shift_gain);
}

/// The best shift found for one pose.
struct CorrelationResult {
  float score = 0.0f;       ///< correlation at the best shift
  float prior_cost = 0.0f;  ///< the motion prior's penalty at the best shift (score units)
  int dx_cells = 0;         ///< best shift in cells (world x)
  int dy_cells = 0;         ///< best shift in cells (world y)
  int dyaw_steps = 0;       ///< best yaw shift in steps
  Pose2 pose;               ///< the input pose moved by the best shift
  int points_used = 0;      ///< distinct cells the points fell in at the unshifted yaw
};

/// Correlates a scan with a map raster over a grid of x/y/yaw shifts around a pose (the laser
/// correlation model, Wang, ECE276A report, Sec. II-D, Eq. 7; the 9x9 grid of Zafari and Kansal).
///
/// The sum over shifts is computed as S x S patch sums: every point is transformed once per yaw
/// to an integer cell, consecutive points in the same cell are counted once, and the S rows of the
/// patch are accumulated row by row in SIMD registers over all points (cache-friendly, no per-shift
/// transform). Scores are float sums in a fixed order, so results are bit-reproducible.
/// Thread-safe.
class MapCorrelator {
 public:
  explicit MapCorrelator(const MapCorrelatorOptions& options);

  const MapCorrelatorOptions& options() const { return options_; }

  /// Best shift for `points_base` (points in the base frame) seen from `world_from_base`, ranked
  /// by score minus the prior's cost; the prior is centred on `world_from_base`.
  /// Ties go to the shift closest to the centre. If `table` is given it receives every score,
  /// indexed [yaw][dy][dx] with dx, dy from -n to n.
  CorrelationResult Correlate(const GridView& grid, std::span<const Eigen::Vector2d> points_base,
                              const Pose2& world_from_base,
                              std::vector<float>* table = nullptr) const;

  /// The same for the occupied-indicator model, reading the walls from `mask` (which must follow
  /// the grid `grid` views, at occupied_threshold): the same result bit for bit, faster.
  CorrelationResult Correlate(const GridView& grid, const OccupiedMask& mask,
                              std::span<const Eigen::Vector2d> points_base,
                              const Pose2& world_from_base,
                              std::vector<float>* table = nullptr) const;

 private:
  CorrelationResult CorrelateImpl(const GridView& grid, const OccupiedMask* mask,
                                  std::span<const Eigen::Vector2d> points_base,
                                  const Pose2& world_from_base, std::vector<float>* table) const;

  MapCorrelatorOptions options_;
};

}  // namespace slamrig::slam
