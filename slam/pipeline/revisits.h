#pragma once

// Whether a finished map agrees with itself where the robot came back. A scan matcher, a filter's
// weights and a pose graph's residuals all judge a scan against the map it is being placed in;
// none of them sees a map that holds two copies of one corridor, each consistent on its own (a
// wrong turn taken early, a loop closure missed). The scans themselves do: where the estimate
// says the robot stood again, at a similar heading, the two views must share most of their
// walls. docs/studies/revisits.md measures it on the ten logs, their noisier copies and the
// generated worlds.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// How two views count as a revisit and when a revisit agrees.
struct RevisitRules {
  double radius_m = 1.0;      ///< the later view's pose this close to the earlier one's
  double max_turn_rad = 1.0;  ///< and its heading this close (a half-circle scan shares most)
  double min_path_m = 5.0;    ///< driven between them: not the same pass
  double reach_m = 15.0;      ///< the later view's points within this of the earlier pose count
  double cell_m = 0.2;        ///< a point agrees within a cell's neighbourhood of the other's
  double min_overlap = 0.2;   ///< a revisit whose best earlier view shares less disagrees ...
  double max_shift_m = 1.0;   ///< ... unless a shift this small brings it to
  double min_shifted_overlap = 0.6;     ///< this share (a map off by less than kDivergedErrorM,
                                        ///< not a second copy; above chance over the shifts)
  int min_points = 20;                  ///< fewer counted points: no verdict on that pair
  int max_candidates = 5;               ///< earlier views compared per revisit (the nearest)
  double max_disagreeing_share = 0.01;  ///< above this share of revisits, and ...
  int min_disagreeing_places = 5;       ///< ... in this many places (radius_m squares), the map
                                        ///< contradicts itself
};

/// The verdict over a run's views (poses with their scans' points in the base frame).
struct RevisitAgreement {
  int revisits = 0;     ///< views with at least one earlier view to compare with
  int disagreeing = 0;  ///< of them, those that share under min_overlap with every such view,
                        ///< even shifted by up to max_shift_m
  int shifted = 0;      ///< of the revisits, those a shift of up to max_shift_m reconciles
  int disagreeing_places = 0;  ///< the radius_m squares the disagreeing views stand in
  /// The views that disagree, by index.
  std::vector<int> disagreeing_views;

  double share() const { return revisits > 0 ? static_cast<double>(disagreeing) / revisits : 0.0; }
  /// More disagreeing revisits, in more places, than clutter explains (a door, a passer-by, a
  /// turn on the spot: one place each): the map holds a second copy of what the robot came back
  /// to.
  bool contradicts(const RevisitRules& rules) const {
    return disagreeing_places >= rules.min_disagreeing_places &&
           share() > rules.max_disagreeing_share;
  }
  /// Adds revisits, revisits_disagreeing and revisits_disagreeing_places to an estimator's
  /// statistics.
  void AppendStatistics(std::map<std::string, double>* statistics) const;
  /// `names` with those three appended.
  static std::vector<std::string> WithStatisticNames(std::vector<std::string> names);
};

/// Compares each view with the nearest earlier views the rules admit (poses in the map's frame,
/// points in each pose's own frame; the two vectors of equal length). Linear in the views and
/// their points, with the candidates found through a grid of the poses.
RevisitAgreement CheckRevisits(const std::vector<Pose2>& poses,
                               const std::vector<std::vector<Eigen::Vector2d>>& points,
                               const RevisitRules& rules = {});

/// The views a filter keeps for the check: its scans' points, one scan every distance_m of travel
/// or turn_rad of turning of its online estimate (the graph's keyframe spacing), checked at the
/// end against its final poses (revised, where the estimator revises its past).
class RevisitViews {
 public:
  static constexpr double kDistanceM = 0.5;
  static constexpr double kTurnRad = 0.35;

  /// Whether the scan placed at `online` (the next scan, counted from 0) is kept: call Keep with
  /// its points if so. Every scan must be offered, in order.
  bool Offer(const Pose2& online);
  /// Keeps the points (base frame) of the scan Offer last accepted.
  void Keep(std::vector<Eigen::Vector2d> points) { points_.push_back(std::move(points)); }
  /// The check at `final_poses` (one per offered scan; a shorter list checks the views it holds).
  RevisitAgreement Check(const std::vector<Pose2>& final_poses,
                         const RevisitRules& rules = {}) const;

 private:
  int offered_ = 0;
  std::optional<Pose2> last_;
  std::vector<int> scans_;
  std::vector<std::vector<Eigen::Vector2d>> points_;
};

}  // namespace slamrig::slam
