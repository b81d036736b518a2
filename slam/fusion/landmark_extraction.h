// Point landmarks from a 2D laser scan: the scan is cut into clusters where consecutive ranges
// jump (Premebida and Nunes, "Segmentation and geometric primitives extraction from 2D laser
// range data for mobile robot applications", 2005, Sec. II), and a cluster counts as a landmark
// when a circle fits it (slam/fusion/circle_fit.h) with a radius in a configured range and a small
// residual that beats a line's and a corner's (two lines'): pillars, posts, table legs. Walls fit
// no small circle; corners (a square column's, a car's) may, but two lines fit them better.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "slam/types/records.h"

namespace slamrig::slam {

/// How clusters are cut and which ones count as round landmarks. Units in the names.
struct LandmarkExtractionOptions {
  /// Consecutive hits further apart than jump_m + jump_rel * range start a new cluster.
  double jump_m = 0.08;
  double jump_rel = 0.03;
  int min_points = 5;          ///< fewer hits than this make no landmark
  double min_radius_m = 0.05;  ///< fitted radii outside [min, max] are not landmarks
  double max_radius_m = 0.5;
  double max_fit_rms_m = 0.02;  ///< root mean square distance of the hits to the fitted circle
  /// A cluster is not round when lines fit it significantly better than the circle: the
  /// probability of the F test on their residual variances (see LinesAreBetter).
  double model_test_probability = 0.99;
  /// Added to the fit's range-bearing covariance (what the fit misses: the beam's width, the
  /// arc's bias when the pillar is seen edge-on).
  double range_sigma_floor_m = 0.01;
  double bearing_sigma_floor_rad = 0.002;

  /// One message per broken rule ("min_points = 2; must be >= 3").
  std::vector<std::string> Validate() const;
};

/// The field table of LandmarkExtractionOptions (slam/config/fields.h).
template <typename V>
void VisitFields(V& v, LandmarkExtractionOptions& o) {
  v("jump_m", o.jump_m);
  v("jump_rel", o.jump_rel);
  v("min_points", o.min_points);
  v("min_radius_m", o.min_radius_m);
  v("max_radius_m", o.max_radius_m);
  v("max_fit_rms_m", o.max_fit_rms_m);
  v("model_test_probability", o.model_test_probability);
  v("range_sigma_floor_m", o.range_sigma_floor_m);
  v("bearing_sigma_floor_rad", o.bearing_sigma_floor_rad);
}

/// The residual of a line model of a cluster (a straight line or a corner) and its degrees of
/// freedom (points less the model's parameters).
struct LinesFit {
  double sse_m2 = 0.0;
  int dof = 0;
};

/// Whether lines explain hits significantly better than a circle: the circle's residual variance
/// (sse / dof) exceeds theirs by more than the F(circle_dof, lines_dof) quantile at `probability`.
/// An F test, approximate (the models are not nested); the residuals of several sightings may be
/// pooled (sums of sse and of dof).
bool LinesAreBetter(double circle_sse_m2, int circle_dof, double lines_sse_m2, int lines_dof,
                    double probability);

/// One round landmark seen in a scan, in base_link (the laser's mount applied).
struct LandmarkObservation {
  double range_m = 0.0;      ///< distance of the circle's centre from base_link's origin
  double bearing_rad = 0.0;  ///< its direction, CCW from base_link's +x
  /// Covariance of (range_m, bearing_rad): the fit's centre covariance through the
  /// range-bearing Jacobian, plus the floors.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();  ///< the centre in base_link
  double radius_m = 0.0;
  double radius_variance_m2 = 0.0;  ///< the fit's, from its residuals
  double circle_sse_m2 = 0.0;       ///< the circle fit's squared residuals
  int circle_dof = 0;               ///< points less 3
  LinesFit lines;                   ///< the better line model's
  double fit_rms_m = 0.0;
  int points = 0;  ///< hits in the cluster
};

/// The round landmarks of `scan`, in beam order, in base_link at the scan's time (beam 0): each
/// centre, fitted in base_link at the time of its cluster's middle beam, is moved back by the
/// scan's SweepPose there (at 1 m/s a 270 degree sweep moves the robot ~2 cm, a bias that repeats
/// at every scan and that no covariance would otherwise hold). `options` must be valid.
std::vector<LandmarkObservation> ExtractLandmarks(const LaserScan& scan,
                                                  const LandmarkExtractionOptions& options);

}  // namespace slamrig::slam
