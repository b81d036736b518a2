// A landmark map (point landmarks: pillars) scored against the true landmarks.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "slam/eval/nees.h"
#include "slam/types/time.h"
#include "slam/types/trajectory.h"

namespace slamrig::slam {

/// An estimated landmark, in the reference's frame.
struct ScoredLandmark {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  ///< of position_m, m^2
};

/// One observation the estimator paired with landmark `landmark` (an index into the landmarks).
struct ScoredSighting {
  Time time;
  int landmark = -1;
  Eigen::Vector2d center_base_m = Eigen::Vector2d::Zero();  ///< the observed centre, base_link
};

/// The scores of a landmark map. The error fields and `anees` are NaN when no pillar is mapped.
struct LandmarkScore {
  int pillars = 0;
  int mapped = 0;    ///< pillars paired with a landmark
  int spurious = 0;  ///< landmarks paired with no pillar
  double error_max_m = 0.0;
  double error_mean_m = 0.0;
  double anees = 0.0;                      ///< mean 2-dof NEES of the pairs
  std::optional<NeesBounds> anees_bounds;  ///< 95 % region of `anees` (with a pair)
  int sightings = 0;
  int wrong_associations = 0;
};

/// Scores `landmarks` against the true `pillars`: each pillar is paired with its nearest
/// landmark when each is the other's nearest and they lie within `match_radius_m`; the errors and
/// the landmark NEES of the pairs; the wrong associations. The pillar of a sighting is the one
/// nearest the observed centre placed at the true pose (`truth` at its time; none beyond the
/// radius: clutter), a landmark's the one most of its sightings are of; a sighting is wrong when
/// its pillar is not its landmark's, or, for a clutter landmark, when it lies further than the
/// radius from where that landmark ended up.
LandmarkScore ScoreLandmarks(const std::vector<Eigen::Vector2d>& pillars,
                             const std::vector<ScoredLandmark>& landmarks,
                             const std::vector<ScoredSighting>& sightings, const Trajectory& truth,
                             double match_radius_m = 0.5);

}  // namespace slamrig::slam
