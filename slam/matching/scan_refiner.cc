// Gauss-Newton scan-to-map alignment on a bilinearly interpolated raster: Kohlbrecher, von Stryk,
// Meyer, Klingauf, "A Flexible and Scalable SLAM System with Full 3D Motion Estimation", SSRR 2011,
// Sec. IV-A (Eqs. 6-13: residual 1 - M(S_i(xi)), the interpolation gradient, the normal equations).
#include "slam/matching/scan_refiner.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// Bilinear interpolation of cell-centre samples and its gradient in world units.
struct Sample {
  double value;
  Eigen::Vector2d gradient;
};

Sample Interpolate(const GridView& g, const Eigen::Vector2d& world) {
  // Continuous cell coordinates with cell centres at integers.
  const double fx = (world.x() - g.origin.x()) / g.resolution - 0.5;
  const double fy = (world.y() - g.origin.y()) / g.resolution - 0.5;
  const double x0 = std::floor(fx), y0 = std::floor(fy);
  const int ix = static_cast<int>(x0), iy = static_cast<int>(y0);
  const double tx = fx - x0, ty = fy - y0;
  const double v00 = g.At(ix, iy), v10 = g.At(ix + 1, iy);
  const double v01 = g.At(ix, iy + 1), v11 = g.At(ix + 1, iy + 1);
  Sample s;
  s.value = (1 - ty) * ((1 - tx) * v00 + tx * v10) + ty * ((1 - tx) * v01 + tx * v11);
  s.gradient.x() = ((1 - ty) * (v10 - v00) + ty * (v11 - v01)) / g.resolution;
  s.gradient.y() = ((1 - tx) * (v01 - v00) + tx * (v11 - v10)) / g.resolution;
  return s;
}

double Square(double v) { return v * v; }

}  // namespace

std::vector<std::string> ScanRefinerOptions::Validate() const {
  std::vector<std::string> errors;
  auto add = [&](const char* field, double got, const char* rule) {
    errors.push_back(RuleViolation(field, got, rule));
  };
  if (max_iterations < 0) add("max_iterations", max_iterations, "must be >= 0");
  if (!(max_step_m > 0.0)) add("max_step_m", max_step_m, "must be > 0");
  if (!(max_step_rad > 0.0)) add("max_step_rad", max_step_rad, "must be > 0");
  if (!(converged_step_m >= 0.0)) add("converged_step_m", converged_step_m, "must be >= 0");
  if (!(prior_sigma_xy_m >= 0.0)) add("prior_sigma_xy_m", prior_sigma_xy_m, "must be >= 0");
  if (!(prior_sigma_yaw_rad >= 0.0)) {
    add("prior_sigma_yaw_rad", prior_sigma_yaw_rad, "must be >= 0");
  }
  return errors;
}

ScanRefiner::ScanRefiner(const ScanRefinerOptions& options) : options_(options) {
  SLAMRIG_CHECK(options_.Validate().empty(), "invalid ScanRefinerOptions");
}

double ScanRefiner::Score(const GridView& raster, std::span<const Eigen::Vector2d> points_base,
                          const Pose2& pose) {
  double sum = 0.0;
  for (const Eigen::Vector2d& p : points_base) sum += Interpolate(raster, pose * p).value;
  return sum;
}

RefineResult ScanRefiner::Refine(const GridView& raster, float max_value,
                                 std::span<const Eigen::Vector2d> points_base,
                                 const Pose2& initial) const {
  return Refine(raster, max_value, points_base, initial, initial);
}

RefineResult ScanRefiner::Refine(const GridView& raster, float max_value,
                                 std::span<const Eigen::Vector2d> points_base, const Pose2& initial,
                                 const Pose2& prior_mean) const {
  // Prior information per unit of score (0: no prior on that part).
  const Eigen::Vector3d info(
      options_.prior_sigma_xy_m > 0.0 ? 1.0 / Square(options_.prior_sigma_xy_m) : 0.0,
      options_.prior_sigma_xy_m > 0.0 ? 1.0 / Square(options_.prior_sigma_xy_m) : 0.0,
      options_.prior_sigma_yaw_rad > 0.0 ? 1.0 / Square(options_.prior_sigma_yaw_rad) : 0.0);
  auto offset = [&](const Pose2& pose) {
    return Eigen::Vector3d(pose.x() - prior_mean.x(), pose.y() - prior_mean.y(),
                           NormalizeAngle(pose.theta() - prior_mean.theta()));
  };
  auto prior_cost = [&](const Pose2& pose) {
    const Eigen::Vector3d d = offset(pose);
    return 0.5 * d.dot(info.cwiseProduct(d));
  };
  RefineResult result{initial, Score(raster, points_base, initial), prior_cost(initial), 0};
  if (!(max_value > 0.0f) || points_base.empty()) return result;
  const double scale = 1.0 / max_value;
  for (int it = 0; it < options_.max_iterations; ++it) {
    const Pose2& pose = result.pose;
    const double c = std::cos(pose.theta()), s = std::sin(pose.theta());
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    double residual_sum = 0.0;
    for (const Eigen::Vector2d& p : points_base) {
      const Sample m = Interpolate(raster, pose * p);
      const double residual = 1.0 - scale * m.value;
      // d(world point)/d(theta) = R' p.
      const Eigen::Vector2d dtheta(-s * p.x() - c * p.y(), c * p.x() - s * p.y());
      const Eigen::Vector3d j(scale * m.gradient.x(), scale * m.gradient.y(),
                              scale * m.gradient.dot(dtheta));
      h += j * j.transpose();
      b += j * residual;
      residual_sum += residual;
    }
    // The prior as extra residuals. The data's gradient is sum r_i scale grad M_i where the
    // score's is sum grad M_i: weighting the prior's information by scale * mean(r_i) makes the
    // two stationary points agree, so the steps head for the maximum of score - prior cost.
    const Eigen::Vector3d w =
        scale * (residual_sum / static_cast<double>(points_base.size())) * info;
    h.diagonal() += w;
    b -= w.cwiseProduct(offset(pose));
    // Levenberg-style damping keeps flat directions (a corridor) from exploding.
    h.diagonal() += Eigen::Vector3d::Constant(1e-6 + 1e-3 * h.trace());
    Eigen::Vector3d step = h.ldlt().solve(b);
    if (!step.allFinite()) break;
    const double t_norm = step.head<2>().norm();
    if (t_norm > options_.max_step_m) step *= options_.max_step_m / t_norm;
    if (std::abs(step.z()) > options_.max_step_rad)
      step *= options_.max_step_rad / std::abs(step.z());
    const Pose2 candidate(pose.x() + step.x(), pose.y() + step.y(), pose.theta() + step.z());
    const double score = Score(raster, points_base, candidate);
    const double cost = prior_cost(candidate);
    ++result.iterations;
    if (!(score - cost > result.score - result.prior_cost)) break;
    result.pose = candidate;
    result.score = score;
    result.prior_cost = cost;
    if (step.head<2>().norm() < options_.converged_step_m && std::abs(step.z()) < 1e-4) break;
  }
  return result;
}

}  // namespace slamrig::slam
