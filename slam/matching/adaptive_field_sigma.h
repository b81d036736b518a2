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
  /// The sigma is this x the smoothed median distance, within [min_m, max_m]. Metres, not map
  /// cells: a real lidar's noise and a real map's blur do not shrink with the cells (intel on a
  /// 0.025 m map ends 0.061 m off with these bounds, 0.156 with [1.2, 1.6] cells; on a 0.1 m map
  /// 0.098 against 2.55). A simulated 1 cm lidar on a fine map wants less: turn it off and set
  /// the sigma (scenarios/office_camera.yaml).
  double residual_factor = 2.5;
  double min_m = 0.06;
  double max_m = 0.08;
  /// Points further than this from every wall (new ground, clutter, a person) are left out of
  /// the median. At most likelihood_field.cutoff_sigmas x min_m: beyond the field's cutoff a
  /// distance cannot be read off it.
  double window_m = 0.15;
  int min_points = 20;  ///< an update with fewer points near a wall is not counted
  /// The smoothed median is the mean of the first 1 / rate updates' medians, then an exponential
  /// average with that memory (each update's median weighs `rate`).
  double rate = 0.01;
  int warmup_updates = 10;  ///< counted updates before the sigma first moves
  /// The sigma moves to its target only when they differ by more than this fraction of it: each
  /// move recomputes the whole field.
  double change_ratio = 0.1;

  /// One message per broken rule, keys relative to this struct (the container names it).
  std::vector<std::string> Validate() const;
};

/// The field table of AdaptiveSigmaOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, AdaptiveSigmaOptions& o) {
  v("enabled", o.enabled);
  v("residual_factor", o.residual_factor);
  v("min_m", o.min_m);
  v("max_m", o.max_m);
  v("window_m", o.window_m);
  v("min_points", o.min_points);
  v("rate", o.rate);
  v("warmup_updates", o.warmup_updates);
  v("change_ratio", o.change_ratio);
}

/// The smoothed median wall distance and the sigma it implies (AdaptiveSigmaOptions).
class AdaptiveFieldSigma {
 public:
  explicit AdaptiveFieldSigma(const AdaptiveSigmaOptions& options);

  /// The median distance to the nearest wall of `points_base` seen from `pose`, read off
  /// `field` (its followed window, view()) as the scan refiner samples it, over the points within
  /// window_m of a wall; nullopt when fewer than min_points are.
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
  double median_m_ = 0.0;
  int updates_ = 0;
  int moves_ = 0;
};

}  // namespace slamrig::slam
