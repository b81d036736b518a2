#include "slam/fusion/landmark_extraction.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/fusion/circle_fit.h"
#include "slam/fusion/consistency.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// Running sums of points, from which the total-least-squares line of any run of them and its
// sum of squared perpendicular distances follow in O(1).
struct Moments {
  double n = 0.0, x = 0.0, y = 0.0, xx = 0.0, xy = 0.0, yy = 0.0;
  void Add(const Eigen::Vector2d& p) {
    n += 1.0;
    x += p.x();
    y += p.y();
    xx += p.x() * p.x();
    xy += p.x() * p.y();
    yy += p.y() * p.y();
  }
  Moments Minus(const Moments& o) const {
    return {n - o.n, x - o.x, y - o.y, xx - o.xx, xy - o.xy, yy - o.yy};
  }
  // The smaller eigenvalue of the scatter matrix: the residual of the best line.
  double LineSse() const {
    if (n < 2.0) return 0.0;
    const double a = xx - x * x / n, b = xy - x * y / n, c = yy - y * y / n;
    return std::max(0.0, 0.5 * (a + c) - std::hypot(0.5 * (a - c), b));
  }
};

// The residual of the better of two line models of `hits`, a straight line or a corner (two
// lines meeting at the best split point), as the one with the smaller unbiased residual variance
// (squared residuals over the degrees of freedom left: n - 2 for the line, n - 4 for the corner's
// two lines; the split, a choice among n - 3 places, is not counted, so that five points, the
// fewest a landmark has, leave the corner one degree of freedom to pool over sightings).
LinesFit FitLines(const std::vector<Eigen::Vector2d>& hits) {
  const int n = static_cast<int>(hits.size());
  std::vector<Moments> prefix(n + 1);
  for (int i = 0; i < n; ++i) {
    prefix[i + 1] = prefix[i];
    prefix[i + 1].Add(hits[i]);
  }
  LinesFit best{prefix[n].LineSse(), n - 2};
  // Each leg has at least two points; the split point belongs to the first.
  for (int k = 2; n >= 5 && k + 2 <= n; ++k) {
    const double sse = prefix[k].LineSse() + prefix[n].Minus(prefix[k]).LineSse();
    if (sse / (n - 4) < best.sse_m2 / best.dof) best = {sse, n - 4};
  }
  return best;
}

// A cluster of hits (laser frame) becomes a landmark when a small circle fits it well.
void FitCluster(const std::vector<Eigen::Vector2d>& hits, std::size_t first_beam,
                const LaserScan& scan, const LandmarkExtractionOptions& o,
                std::vector<LandmarkObservation>* out) {
  if (static_cast<int>(hits.size()) < o.min_points) return;
  // A cluster wider than the largest pillar is a wall, whatever a circle makes of it.
  if ((hits.back() - hits.front()).norm() > 2.0 * o.max_radius_m) return;
  const std::optional<CircleFit> fit = FitCircle(hits);
  if (!fit || fit->radius_m < o.min_radius_m || fit->radius_m > o.max_radius_m ||
      fit->rms_m > o.max_fit_rms_m) {
    return;
  }
  // A corner (a square column's, a car's) or a short wall can fit a small circle under
  // max_fit_rms_m; lines then fit it to the noise, and the circle's residual variance exceeds
  // theirs by more than chance allows (an F test at model_test_probability, approximate: the
  // models are not nested). With few points the test has little power; EkfSlam pools it over a
  // tentative landmark's sightings (LinesAreBetter).
  const double circle_sse = fit->rms_m * fit->rms_m * static_cast<double>(hits.size());
  const LinesFit lines = FitLines(hits);
  if (LinesAreBetter(circle_sse, static_cast<int>(hits.size()) - 3, lines.sse_m2, lines.dof,
                     o.model_test_probability)) {
    return;
  }
  // The centre must lie beyond the hits (the laser sees the near side of a convex object): a
  // concave arc (the inside of a rounded corner) fits a circle centred towards the laser.
  const Eigen::Vector2d mid = hits[hits.size() / 2];
  if (fit->center.norm() <= mid.norm()) return;
  const Pose2& mount = scan.base_from_laser;
  const Eigen::Matrix2d rotation = mount.Rotation();
  const Eigen::Vector2d center_then = mount.translation() + rotation * fit->center;
  // base_link at the scan's time from base_link at the middle beam's.
  const Pose2 start_from_then = scan.SweepPose(first_beam + hits.size() / 2);
  const Eigen::Vector2d center = start_from_then * center_then;
  const Eigen::Matrix2d turn_rotation = start_from_then.Rotation();
  const Eigen::Matrix2d center_covariance = turn_rotation * rotation * fit->center_covariance *
                                            rotation.transpose() * turn_rotation.transpose();
  LandmarkObservation z;
  z.range_m = center.norm();
  z.bearing_rad = std::atan2(center.y(), center.x());
  // d(range, bearing) / d(centre).
  Eigen::Matrix2d j;
  j << center.x() / z.range_m, center.y() / z.range_m, -center.y() / (z.range_m * z.range_m),
      center.x() / (z.range_m * z.range_m);
  z.covariance = j * center_covariance * j.transpose();
  z.covariance(0, 0) += o.range_sigma_floor_m * o.range_sigma_floor_m;
  z.covariance(1, 1) += o.bearing_sigma_floor_rad * o.bearing_sigma_floor_rad;
  z.center_m = center;
  z.radius_m = fit->radius_m;
  z.radius_variance_m2 = fit->radius_variance;
  z.circle_sse_m2 = circle_sse;
  z.circle_dof = static_cast<int>(hits.size()) - 3;
  z.lines = lines;
  z.fit_rms_m = fit->rms_m;
  z.points = static_cast<int>(hits.size());
  out->push_back(z);
}

}  // namespace

bool LinesAreBetter(double circle_sse_m2, int circle_dof, double lines_sse_m2, int lines_dof,
                    double probability) {
  if (circle_dof < 1 || lines_dof < 1) return false;
  const double circle_variance = circle_sse_m2 / circle_dof;
  const double lines_variance = lines_sse_m2 / lines_dof;
  return circle_variance > FQuantile(probability, circle_dof, lines_dof) * lines_variance;
}

std::vector<std::string> LandmarkExtractionOptions::Validate() const {
  Rules rules;
  rules.Positive("jump_m", jump_m)
      .NonNegative("jump_rel", jump_rel)
      .Require(min_points >= 4, "min_points", min_points, "must be >= 4 (a circle has 3 dof)")
      .Positive("min_radius_m", min_radius_m)
      .Require(max_radius_m > min_radius_m, "max_radius_m", max_radius_m, "must be > min_radius_m")
      .Positive("max_fit_rms_m", max_fit_rms_m)
      .Require(model_test_probability >= 0.5 && model_test_probability < 1.0,
               "model_test_probability", model_test_probability, "must be in [0.5, 1)")
      .Positive("range_sigma_floor_m", range_sigma_floor_m)
      .Positive("bearing_sigma_floor_rad", bearing_sigma_floor_rad);
  return rules.errors();
}

std::vector<LandmarkObservation> ExtractLandmarks(const LaserScan& scan,
                                                  const LandmarkExtractionOptions& options) {
  SLAMRIG_CHECK_VALID(options, "LandmarkExtractionOptions");
  std::vector<LandmarkObservation> out;
  std::vector<Eigen::Vector2d> cluster;
  std::size_t first = 0;  // the cluster's first beam
  double previous_range = 0.0;
  // A cluster ends at a range jump or a beam without a return. The first and last clusters are
  // kept too: the scan's edge cuts them like an occlusion would.
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    if (!scan.IsHit(i) || !std::isfinite(scan.ranges_m[i])) {
      FitCluster(cluster, first, scan, options, &out);
      cluster.clear();
      continue;
    }
    const double range = scan.ranges_m[i];
    if (!cluster.empty() &&
        std::abs(range - previous_range) > options.jump_m + options.jump_rel * range) {
      FitCluster(cluster, first, scan, options, &out);
      cluster.clear();
    }
    if (cluster.empty()) first = i;
    const double angle = scan.BeamAngle(i);
    cluster.emplace_back(range * std::cos(angle), range * std::sin(angle));
    previous_range = range;
  }
  FitCluster(cluster, first, scan, options, &out);
  return out;
}

}  // namespace slamrig::slam
