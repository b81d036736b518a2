#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "slam/matching/likelihood_field.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// A likelihood-field sigma that follows the map's own sharpness. A matched scan's points lie
/// some way off the walls its map holds: the map's cells, the scan's noise and the map's own
/// blur (walls drawn from scans a metre apart, seen at long range, a little off each other). The
/// median of those distances over the points near a wall, smoothed over updates, measures that
/// blur, and the field's sigma is a multiple of it between two bounds. On the corrected logs at
/// sigma 0.08 the median is 0.017-0.020 m on freiburg-079, freiburg-101, intel and belgioioso and
/// 0.036-0.042 m on aces, acapulco and edmonton; a fixed 0.05 closed freiburg-079 and bettered
/// intel but doubled acapulco's error and lost aces, a fixed 0.1 did the reverse (README, "the
/// likelihood field's sigma").
struct AdaptiveSigmaOptions {
  /// On by default; off, the field keeps its sigma_m (README, "a field sigma that follows the
  /// map").
  bool enabled = true;
  /// The sigma is this x the smoothed median distance, within [min_cells, max_cells] cells of
  /// the map (0.06-0.08 m on a 0.05 m map). In cells, not metres: the median holds the cells'
  /// own quantisation, so a finer map earns a sharper field (office_loop on a 0.025 m map ends
  /// 0.029 m off with these bounds, 0.087 m with the 0.05 m map's 0.06-0.08 m).
  double residual_factor = 2.5;
  double min_cells = 1.2;
  double max_cells = 1.6;
  /// Points further than this many cells from every wall (new ground, clutter, a person) are
  /// left out of the median. At most likelihood_field.cutoff_sigmas x min_cells: beyond the
  /// field's cutoff a distance cannot be read off it.
  double window_cells = 3.0;
  int min_points = 20;  ///< an update with fewer points near a wall is not counted
  /// The smoothed median is the mean of the first 1 / rate updates' medians, then an exponential
  /// average with that memory (each update's median weighs `rate`).
  double rate = 0.01;
  int warmup_updates = 10;  ///< counted updates before the sigma first moves
  /// The sigma moves to its target only when they differ by more than this fraction of it: each
  /// move recomputes the whole field.
  double change_ratio = 0.1;

  /// One message per broken rule (prefixed "adaptive_sigma.").
  std::vector<std::string> Validate() const;
};

/// The field table of AdaptiveSigmaOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, AdaptiveSigmaOptions& o) {
  v("enabled", o.enabled);
  v("residual_factor", o.residual_factor);
  v("min_cells", o.min_cells);
  v("max_cells", o.max_cells);
  v("window_cells", o.window_cells);
  v("min_points", o.min_points);
  v("rate", o.rate);
  v("warmup_updates", o.warmup_updates);
  v("change_ratio", o.change_ratio);
}

/// The smoothed median wall distance and the sigma it implies (AdaptiveSigmaOptions).
class AdaptiveFieldSigma {
 public:
  /// `cell_m`: the map's (and so the field's) cell size, the unit of the bounds and the window.
  AdaptiveFieldSigma(const AdaptiveSigmaOptions& options, double cell_m);

  /// The median distance to the nearest wall of `points_base` seen from `pose`, read off
  /// `field` (its whole raster, view()) as the scan refiner samples it, over the points within
  /// window_cells of a wall; nullopt when fewer than min_points are.
  std::optional<double> MedianWallDistance(const LikelihoodField& field,
                                           std::span<const Eigen::Vector2d> points_base,
                                           const Pose2& pose) const;
  /// Takes one update's median; the sigma the field should move to from `sigma_in_use_m` (its
  /// own, LikelihoodField::sigma_m()), or nullopt to keep it.
  std::optional<double> Observe(double median_m, double sigma_in_use_m);

  /// The smoothed median wall distance (0 before the first update).
  double median_m() const { return median_m_; }
  int moves() const { return moves_; }

 private:
  AdaptiveSigmaOptions options_;
  double cell_m_ = 0.0;
  double median_m_ = 0.0;
  int updates_ = 0;
  int moves_ = 0;
};

}  // namespace slamrig::slam
