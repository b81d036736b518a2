#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "slam/matching/match_result.h"
#include "slam/matching/point_kd_tree.h"
#include "slam/matching/scan_points.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// The error ICP minimises.
enum class IcpMetric {
  /// Sum of squared point distances, solved in closed form per iteration (Besl and McKay, "A
  /// Method for Registration of 3-D Shapes", PAMI 1992; in 2D the SVD/Kabsch step is one atan2).
  kPointToPoint,
  /// Sum of squared distances to the reference's local lines (Censi, "An ICP variant using a
  /// point-to-line metric", ICRA 2008: the squared distance to the segment through the two nearest
  /// reference points, here the line fitted to the neighbours), linearised and solved by
  /// Gauss-Newton per iteration.
  kPointToLine,
};

/// The robust weight of a residual r (iteratively reweighted least squares).
enum class RobustKernel {
  kNone,    ///< w = 1
  kHuber,   ///< w = 1 for |r| <= k, else k / |r|
  kCauchy,  ///< w = 1 / (1 + (r / k)^2)
};

/// ICP parameters.
struct IcpOptions {
  IcpMetric metric = IcpMetric::kPointToLine;
  int max_iterations = 50;                     ///< iteration cap
  double converged_translation_m = 1e-4;       ///< converged when a step moves less than this ...
  double converged_rotation_rad = 1e-4;        ///< ... and turns less than this
  double max_correspondence_distance_m = 0.5;  ///< farther nearest neighbours are no pair
  /// Trimmed ICP (Chetverikov et al., ICPR 2002): keep this share of the pairs with the smallest
  /// residuals each iteration, in (0, 1]; 1 keeps all.
  double trim_fraction = 1.0;
  RobustKernel kernel = RobustKernel::kNone;
  double kernel_scale_m = 0.05;  ///< k of the robust kernel
  /// Point-to-line: the reference's normals come from the principal axes of each point's
  /// neighbours (itself included; thin the reference, e.g. ScanPointsOptions::voxel_size_m, to a
  /// spacing well above the range noise, or the normals are noise) ...
  int normal_neighbors = 10;
  /// ... within this distance; a point with fewer than 3 such neighbours has no normal and no
  /// point-to-line pair.
  double normal_radius_m = 0.5;
  int min_correspondences = 10;  ///< fewer pairs in an iteration: the match fails

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// Iterative closest point on 2D point sets: aligns a source point set (a scan in its base frame)
/// to a fixed reference (another scan, or a local map given as points), starting from an initial
/// guess such as the odometry prior. Correspondences are nearest neighbours in a k-d tree of the
/// reference, gated by distance, trimmed and robustly weighted.
///
/// Covariance: the Gauss-Newton approximation of the final residuals' Hessian,
/// Sigma = sigma^2 (J^T W J)^-1, with J the Jacobian of every kept residual with respect to
/// (x, y, yaw) at the final pose and sigma^2 = sum w r^2 / (m - 3) the residual variance over the m
/// scalar residuals. This is Censi's closed form ("An accurate closed-form estimate of ICP's
/// covariance", ICRA 2007: (d2J/dx2)^-1 d2J/dzdx cov(z) (d2J/dzdx)^T (d2J/dx2)^-1) for isotropic
/// noise on the source points with the terms in the residuals themselves dropped (they vanish at a
/// perfect fit), and with the reference taken as exact: against a reference as noisy as the source,
/// the true spread is up to twice as large. Eigenvalues of J^T W J below 1e-9 of the largest are
/// raised to that floor, so a degenerate direction (a corridor's axis under point-to-line) shows as
/// a huge but finite variance, or, when noise in the normals keeps it finite, as a large ratio to
/// the other direction's. Point-to- point's Hessian does not see such degeneracy: use point-to-line
/// when the covariance matters. Deterministic; Match is thread-safe.
class IcpMatcher {
 public:
  /// Indexes `reference` (points in the reference frame) for matching.
  IcpMatcher(const IcpOptions& options, std::vector<Eigen::Vector2d> reference);

  const IcpOptions& options() const { return options_; }
  const std::vector<Eigen::Vector2d>& reference() const { return tree_.points(); }
  /// The k-d tree over reference(), in its order.
  const PointKdTree& tree() const { return tree_; }
  /// Whether the reference points have normals (point-to-line).
  bool has_normals() const { return options_.metric == IcpMetric::kPointToLine; }
  /// The unit normal of reference point `i` ((0, 0) where it has none, and for point-to-point).
  /// Computed when first asked for (a match asks only for its pairs' points), kept; thread-safe.
  Eigen::Vector2d Normal(std::uint32_t i) const;

  /// Aligns `source` (points in the source's own frame) to the reference from
  /// `reference_from_source_guess`. Fails (std::nullopt) when an iteration has fewer than
  /// min_correspondences pairs. A match that hits the iteration cap is returned with
  /// converged = false.
  std::optional<MatchResult> Match(std::span<const Eigen::Vector2d> source,
                                   const Pose2& reference_from_source_guess) const;

  /// Scan-to-scan ICP: the pose of `source`'s base frame in `reference`'s base frame, both scans
  /// turned into points by `points`.
  static std::optional<MatchResult> MatchScans(const IcpOptions& options,
                                               const ScanPointsOptions& points,
                                               const LaserScan& reference, const LaserScan& source,
                                               const Pose2& reference_from_source_guess);

 private:
  Eigen::Vector2d ComputeNormal(std::uint32_t i) const;

  IcpOptions options_;
  PointKdTree tree_;
  // Point-to-line: one normal per reference point, and its state (empty, being written, ready):
  // the first caller of Normal(i) to claim it writes it; one that loses the race returns the
  // value it computed itself, the same.
  mutable std::vector<Eigen::Vector2d> normals_;
  mutable std::vector<std::atomic<std::uint8_t>> normal_state_;
};

}  // namespace slamrig::slam
