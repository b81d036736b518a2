#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "slam/grid/occupancy_grid.h"
#include "slam/matching/grid_view.h"
#include "slam/matching/match_result.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// The search window and acceptance of the correlative scan matcher.
struct CorrelativeMatcherOptions {
  double linear_window_m = 7.0;  ///< search x and y within +-this of the initial guess
  double angular_window_rad = 3.14159265358979;  ///< search yaw within +-this
  /// Yaw step; 0 = from the scan's farthest point d_max so that no point moves more than a cell
  /// between steps: acos(1 - r^2 / (2 d_max^2)) (Hess et al. 2016, Sec. V).
  double angular_step_rad = 0.0;
  /// Levels of precomputation grids: the coarsest branch-and-bound nodes span 2^(depth-1) cells
  /// in x and y. 1 = exhaustive search; at most 12 (each level is a padded copy of the raster).
  int branch_and_bound_depth = 7;
  /// A pose is only accepted when the mean raster value over the points reaches this; no pose in
  /// the window does: the match fails.
  double min_score = 0.5;
  /// Covariance: the window of finest-level poses around the best (+-cells in x and y, +-yaw
  /// steps) whose scores are weighted ...
  int covariance_half_cells = 5;
  int covariance_half_steps = 5;
  /// ... by exp((score - best score) / covariance_score_scale).
  double covariance_score_scale = 0.02;

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// Real-time correlative scan matching (Olson, "Real-Time Correlative Scan Matching", ICRA 2009)
/// with the exact multi-resolution search of Hess et al., "Real-Time Loop Closure in 2D LIDAR
/// SLAM", ICRA 2016, Sec. V: precomputation grids (Sec. V-C: each cell of level h holds the maximum
/// of the 2^h x 2^h raster cells above and right of it) bound the score of a whole block of
/// translations, and a branch and bound visits the blocks best bound first (best-first, where
/// Sec. V-A goes depth-first), so that it scores only the blocks whose bound reaches the answer.
///
/// The search is over the discrete poses (x0 + i r, y0 + j r, yaw0 + k s) of the window, with r the
/// raster's resolution and s the yaw step. The scan at yaw index k is discretised once: point p's
/// cell is c_k(p) = floor((Pose2(x0, y0, yaw0 + k s) * p - origin) / r), and the pose (i, j, k)
/// scores sum_p raster(c_k(p) + (i, j)) / n in float, in point order, cells outside reading 0. The
/// result is exactly the exhaustive search's best pose and score; ties go to the smallest (k, j,
/// i), the order in which the exhaustive search lists them.
///
/// Covariance (Olson 2009's estimate from the score distribution): the weighted mean and spread of
/// the poses in a small window around the best, each weighted by exp((score - best) /
/// covariance_score_scale), a softmax that treats the score as a log-likelihood up to scale; r^2 /
/// 12 and s^2 / 12 are added for the discretisation. Along a direction where the score is flat (a
/// corridor's axis) the variance reaches the window's (2n + 1)^2 r^2 / 12: read it as "at least
/// that".
///
/// The raster is copied; values should be >= 0 (probabilities, a likelihood field). Deterministic
/// and thread-safe.
class CorrelativeMatcher {
 public:
  /// Precomputes the search grids of `raster`.
  CorrelativeMatcher(const CorrelativeMatcherOptions& options, const GridView& raster);
  CorrelativeMatcher(const CorrelativeMatcher&) = default;
  CorrelativeMatcher(CorrelativeMatcher&&) = default;
  CorrelativeMatcher& operator=(const CorrelativeMatcher&) = default;
  CorrelativeMatcher& operator=(CorrelativeMatcher&&) = default;
  /// Hands its search grids to the next matcher built on this thread (RasterPool).
  ~CorrelativeMatcher();
  /// Searches an occupancy grid: a cell's value is its occupancy probability when it is more
  /// likely occupied than not (log-odds > 0), else 0. With `decimation` d > 1 the search runs on
  /// a raster d times coarser (cells of d x d grid cells from the grid's origin, each holding the
  /// largest value of its block, so no wall is lost): d^2 fewer translations and, with the yaw
  /// step derived from the resolution, d times fewer headings; for a global search whose poses
  /// are refined at the grid's resolution afterwards.
  /// With `region` (world coordinates), only the grid's cells in it count (the rest read 0): the
  /// precomputation then costs the region's area, not the map's.
  CorrelativeMatcher(const CorrelativeMatcherOptions& options, const OccupancyGrid& grid,
                     int decimation = 1,
                     const std::optional<Eigen::AlignedBox2d>& region = std::nullopt);

  const CorrelativeMatcherOptions& options() const { return options_; }

  /// The best pose of `points_base` (points in the base frame) in the window around `initial`,
  /// or std::nullopt when no pose reaches min_score (or there are no points). `iterations` counts
  /// the branch-and-bound nodes scored.
  std::optional<MatchResult> Match(std::span<const Eigen::Vector2d> points_base,
                                   const Pose2& initial) const;

  /// Up to `count` best poses of the window that are distinct places, best first (greedy
  /// non-maximum suppression, each search exact): the first is Match's, and each next one is the
  /// best pose farther than `min_distance_m` in x and y or `min_angle_rad` in yaw from every
  /// earlier one. Fewer when fewer reach min_score. `iterations` counts the nodes of all searches.
  std::vector<MatchResult> MatchDistinct(std::span<const Eigen::Vector2d> points_base,
                                         const Pose2& initial, int count, double min_distance_m,
                                         double min_angle_rad) const;

  /// The yaw step Match uses for `points_base`.
  double AngularStep(std::span<const Eigen::Vector2d> points_base) const;

  /// The bound of precomputation level `level` (0 to depth - 1) at raster cell (x, y): the
  /// largest raster value in cells [x, x + 2^level) x [y, y + 2^level), cells outside the raster
  /// reading 0; 0 outside the level itself (x or y below 1 - 2^level or past the raster).
  float LevelBound(int level, int x, int y) const;

 private:
  // One precomputation grid: covers cells [-offset, width - offset) of the raster in x (and y).
  struct Level {
    int offset = 0;
    int width = 0;
    int height = 0;
    std::vector<float> values;
  };
  void Precompute(std::vector<float> values, int width, int height);
  // A scan's points as raster cells at each yaw of the window, with their bounding boxes.
  struct DiscreteScan;
  DiscreteScan Discretise(std::span<const Eigen::Vector2d> points_base, const Pose2& initial,
                          double step, int half_steps) const;
  // The sum of level `level` over the scan at yaw k shifted by (i, j) cells, in point order.
  float ScoreAt(const DiscreteScan& scan, int level, int k, int i, int j) const;
  // The covariance of the pose (k, i, j) that scored `score` per point, from the score-weighted
  // spread of the poses around it (Olson 2009).
  Eigen::Matrix3d OlsonCovariance(const DiscreteScan& scan, int k, int i, int j, double score,
                                  double step) const;

  CorrelativeMatcherOptions options_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  double resolution_ = 1.0;
  std::vector<Level> levels_;  // levels_[h]: blocks of 2^h cells
};

}  // namespace slamrig::slam
