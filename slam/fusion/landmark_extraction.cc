#include "slam/fusion/landmark_extraction.h"

#include <cmath>

#include "slam/fusion/circle_fit.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// A cluster of hits (laser frame) becomes a landmark when a small circle fits it well.
void FitCluster(const std::vector<Eigen::Vector2d>& hits, std::size_t first_beam,
                const LaserScan& scan, const LandmarkExtractionOptions& o,
                const BaseVelocity& velocity, std::vector<LandmarkObservation>* out) {
  if (static_cast<int>(hits.size()) < o.min_points) return;
  // A cluster wider than the largest pillar is a wall, whatever a circle makes of it.
  if ((hits.back() - hits.front()).norm() > 2.0 * o.max_radius_m) return;
  const std::optional<CircleFit> fit = FitCircle(hits);
  if (!fit || fit->radius_m < o.min_radius_m || fit->radius_m > o.max_radius_m ||
      fit->rms_m > o.max_fit_rms_m) {
    return;
  }
  // The centre must lie beyond the hits (the laser sees the near side of a convex object): a
  // concave arc (the inside of a rounded corner) fits a circle centred towards the laser.
  const Eigen::Vector2d mid = hits[hits.size() / 2];
  if (fit->center.norm() <= mid.norm()) return;
  const Pose2& mount = scan.base_from_laser;
  const double c = std::cos(mount.theta()), s = std::sin(mount.theta());
  Eigen::Matrix2d rotation;
  rotation << c, -s, s, c;
  const Eigen::Vector2d center_then = mount.translation() + rotation * fit->center;
  // base_link at the scan's time from base_link at the middle beam's: an arc at constant speed.
  const double dt = static_cast<double>(first_beam + hits.size() / 2) * scan.time_increment_s;
  const double turn = velocity.yaw_rate_rad_s * dt;
  const double travel = velocity.forward_m_s * dt;
  const Pose2 start_from_then(travel * std::cos(0.5 * turn), travel * std::sin(0.5 * turn), turn);
  const Eigen::Vector2d center = start_from_then * center_then;
  const double ct = std::cos(turn), st = std::sin(turn);
  Eigen::Matrix2d turn_rotation;
  turn_rotation << ct, -st, st, ct;
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
  z.fit_rms_m = fit->rms_m;
  z.points = static_cast<int>(hits.size());
  out->push_back(z);
}

}  // namespace

std::vector<std::string> LandmarkExtractionOptions::Validate() const {
  std::vector<std::string> errors;
  if (!(jump_m > 0.0)) errors.push_back(RuleViolation("jump_m", jump_m, "must be > 0"));
  if (!(jump_rel >= 0.0)) errors.push_back(RuleViolation("jump_rel", jump_rel, "must be >= 0"));
  if (min_points < 4) {
    errors.push_back(RuleViolation("min_points", min_points, "must be >= 4 (a circle has 3 dof)"));
  }
  if (!(min_radius_m > 0.0))
    errors.push_back(RuleViolation("min_radius_m", min_radius_m, "must be > 0"));
  if (!(max_radius_m > min_radius_m)) {
    errors.push_back(RuleViolation("max_radius_m", max_radius_m, "must be > min_radius_m"));
  }
  if (!(max_fit_rms_m > 0.0))
    errors.push_back(RuleViolation("max_fit_rms_m", max_fit_rms_m, "must be > 0"));
  if (!(range_sigma_floor_m > 0.0)) {
    errors.push_back(RuleViolation("range_sigma_floor_m", range_sigma_floor_m, "must be > 0"));
  }
  if (!(bearing_sigma_floor_rad > 0.0)) {
    errors.push_back(
        RuleViolation("bearing_sigma_floor_rad", bearing_sigma_floor_rad, "must be > 0"));
  }
  return errors;
}

std::vector<LandmarkObservation> ExtractLandmarks(const LaserScan& scan,
                                                  const LandmarkExtractionOptions& options,
                                                  const BaseVelocity& velocity) {
  SLAMRIG_CHECK(options.Validate().empty(), "ExtractLandmarks: invalid options");
  std::vector<LandmarkObservation> out;
  std::vector<Eigen::Vector2d> cluster;
  std::size_t first = 0;  // the cluster's first beam
  double previous_range = 0.0;
  // A cluster ends at a range jump or a beam without a return. The first and last clusters are
  // kept too: the scan's edge cuts them like an occlusion would.
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    if (!scan.IsHit(i) || !std::isfinite(scan.ranges_m[i])) {
      FitCluster(cluster, first, scan, options, velocity, &out);
      cluster.clear();
      continue;
    }
    const double range = scan.ranges_m[i];
    if (!cluster.empty() &&
        std::abs(range - previous_range) > options.jump_m + options.jump_rel * range) {
      FitCluster(cluster, first, scan, options, velocity, &out);
      cluster.clear();
    }
    if (cluster.empty()) first = i;
    const double angle = scan.BeamAngle(i);
    cluster.emplace_back(range * std::cos(angle), range * std::sin(angle));
    previous_range = range;
  }
  FitCluster(cluster, first, scan, options, velocity, &out);
  return out;
}

}  // namespace slamrig::slam
