#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "slam/grid/tiled_grid.h"
#include "slam/matching/scan_points.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// The per-particle scan matcher of GMapping (Grisetti, Stachniss, Burgard, "Improved Techniques
/// for Grid Mapping with Rao-Blackwellized Particle Filters", IEEE T-RO 23(1), 2007, Sec. IV;
/// the `ScanMatcher` of the openslam gmapping code): each end point looks for the nearest
/// occupied cell in a small kernel around its cell whose counterpart one cell back along the beam
/// is not occupied (so a wall is only matched from the side the beam came from).
struct RbpfMatcherOptions {
  int kernel_cells = 1;
  /// Match a wall cell only if the cell one step back along the beam is not a wall (the paper's
  /// test; a grazing beam then finds no match on its own wall). false: the nearest wall cell.
  bool free_cell_test = true;        ///< search -n..n cells around each end point's cell
  double score_sigma_m = 0.05;       ///< hill-climbing score per point exp(-d^2 / (2 sigma^2))
  double likelihood_sigma_m = 0.05;  ///< per-point log-likelihood -d^2 / (2 sigma^2)
  /// Log-likelihood of a point with no matching wall in its kernel, and the floor of a matched one.
  double no_match_log_likelihood = -2.0;
  double linear_step_m = 0.05;     ///< first hill-climbing step in x and y (halved on no gain)
  double angular_step_rad = 0.05;  ///< first hill-climbing step in yaw
  /// Before climbing, try yaws within +-yaw_search_rad of the start in steps of
  /// yaw_search_step_rad and climb from the best: odometry that turns 0.15 rad wrong in one slow
  /// step (freiburg-079) is beyond the climb's reach otherwise. 0 = no search.
  double yaw_search_rad = 0.3;
  double yaw_search_step_rad = 0.02;
  int refinements = 3;       ///< step halvings before the climb stops
  int max_iterations = 100;  ///< bound on the climb's steps
  /// Weight of the motion prior in the climb (score units per unit of squared Mahalanobis
  /// distance / 2 from the predicted pose): along a direction the scan does not constrain (a
  /// corridor's axis) the climb then stays with the odometry instead of sliding. 0 = none.
  double prior_weight = 1.0;
  /// A match that explains fewer points than this fraction failed: the particle then moves by
  /// the odometry model alone.
  double min_matched_fraction = 0.3;

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of RbpfMatcherOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, RbpfMatcherOptions& o) {
  v("kernel_cells", o.kernel_cells);
  v("free_cell_test", o.free_cell_test);
  v("score_sigma_m", o.score_sigma_m);
  v("likelihood_sigma_m", o.likelihood_sigma_m);
  v("no_match_log_likelihood", o.no_match_log_likelihood);
  v("linear_step_m", o.linear_step_m);
  v("angular_step_rad", o.angular_step_rad);
  v("yaw_search_rad", o.yaw_search_rad);
  v("yaw_search_step_rad", o.yaw_search_step_rad);
  v("refinements", o.refinements);
  v("max_iterations", o.max_iterations);
  v("prior_weight", o.prior_weight);
  v("min_matched_fraction", o.min_matched_fraction);
}

/// One beam for matching, in the base frame: its end point and the point one cell back toward
/// the laser.
struct MatchPoint {
  Eigen::Vector2d hit;
  Eigen::Vector2d free;
  /// The share of one independent piece of evidence this point is (IndependenceWeights): its
  /// log-likelihood counts this much in MatchFit::weighted_log_likelihood.
  double weight = 1.0;
};

/// The beams `points` selects, with their free points `free_offset_m` back along each beam.
std::vector<MatchPoint> MakeMatchPoints(const LaserScan& scan, const ScanPointsOptions& points,
                                        double free_offset_m);

/// How many of `points`' end points are independent evidence at correlation length `length_m`:
/// the size of the subset kept when, in beam order, a point is kept if it is at least `length_m`
/// from every point kept before it (a maximal `length_m`-separated subset, the packing number of
/// the end points at that scale). Dense beams along a wall of length l give about l / length_m + 1,
/// points farther apart than `length_m` count one each. 0 for no points; all of them for
/// `length_m` <= 0. Invariant under rotations and translations of the scan; deterministic.
int CountIndependentPoints(std::span<const MatchPoint> points, double length_m);

/// Sets every point's weight to 1 / (the number of end points closer than `length_m` to its own,
/// itself included): a cluster of n points that read the same few map cells, and so share their
/// errors, counts as one piece of evidence in total, a point with no neighbour that close counts
/// fully. Per point, where CountIndependentPoints gives one factor for the whole scan. All weights
/// 1 for `length_m` <= 0. Invariant under rotations and translations of the scan; deterministic.
void AssignIndependenceWeights(std::span<MatchPoint> points, double length_m);

/// A scan evaluated at one pose against one map.
struct MatchFit {
  double score = 0.0;           ///< sum of exp(-d^2 / (2 score_sigma^2)) over matched points
  double log_likelihood = 0.0;  ///< sum of the per-point log-likelihoods
  /// Sum of the per-point log-likelihoods times the points' weights (MatchPoint::weight).
  double weighted_log_likelihood = 0.0;
  int matched = 0;  ///< points with a wall in their kernel
};

/// A Gaussian motion prior on the pose: centred on `mean`, isotropic in x, y.
struct PosePrior {
  Pose2 mean;
  double sigma_xy_m = 1.0;
  double sigma_yaw_rad = 1.0;
};

/// The hill-climbed pose and its fit (score and matched; log_likelihood is left 0).
struct ClimbResult {
  Pose2 pose;
  MatchFit fit;
  int evaluations = 0;  ///< poses scored
};

/// Thread-safe (const); the map is read, never written.
class RbpfMatcher {
 public:
  explicit RbpfMatcher(const RbpfMatcherOptions& options);

  const RbpfMatcherOptions& options() const { return options_; }

  /// The fit of `points` seen from `world_from_base` in `map`.
  MatchFit Evaluate(const TiledGrid& map, std::span<const MatchPoint> points,
                    const Pose2& world_from_base) const;

  /// The yaw search (yaw_search_rad), then GMapping's `optimize`: from the best yaw, step +-x, +-y,
  /// +-yaw to the best neighbour while the objective rises; halve the steps when it does not,
  /// `refinements` times. The objective is the score minus prior_weight times half the squared
  /// Mahalanobis distance to `prior`.
  ClimbResult Climb(const TiledGrid& map, std::span<const MatchPoint> points, const Pose2& initial,
                    const PosePrior& prior) const;

 private:
  // The fit; without kLikelihood only `score` and `matched` (the climb needs no more).
  template <bool kLikelihood>
  MatchFit Fit(const TiledGrid& map, std::span<const MatchPoint> points,
               const Pose2& world_from_base) const;

  // exp(-d^2 / (2 score_sigma^2)), from a table.
  double ScoreOf(double d2) const;

  static constexpr int kScoreTableSize = 1024;
  RbpfMatcherOptions options_;
  double likelihood_scale_ = 0.0;  // -1 / (2 sigma^2)
  double score_table_step_ = 0.0;  // d^2 between table entries
  std::vector<double> score_table_;
};

}  // namespace slamrig::slam
