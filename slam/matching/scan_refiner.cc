// Gauss-Newton scan-to-map alignment on a bilinearly interpolated raster: Kohlbrecher, von Stryk,
// Meyer, Klingauf, "A Flexible and Scalable SLAM System with Full 3D Motion Estimation", SSRR 2011,
// Sec. IV-A (Eqs. 6-13: residual 1 - M(S_i(xi)), the interpolation gradient, the normal equations).
#include "slam/matching/scan_refiner.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

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
  double v00, v10, v01, v11;
  if (ix >= 0 && iy >= 0 && ix + 1 < g.width && iy + 1 < g.height) {
    // Inside: the four samples without At()'s bounds checks (the same values).
    const int stride = g.row_stride();
    const float* row = g.values + static_cast<std::ptrdiff_t>(iy) * stride + ix;
    v00 = row[0];
    v10 = row[1];
    v01 = row[stride];
    v11 = row[stride + 1];
  } else {
    v00 = g.At(ix, iy);
    v10 = g.At(ix + 1, iy);
    v01 = g.At(ix, iy + 1);
    v11 = g.At(ix + 1, iy + 1);
  }
  Sample s;
  s.value = (1 - ty) * ((1 - tx) * v00 + tx * v10) + ty * ((1 - tx) * v01 + tx * v11);
  s.gradient.x() = ((1 - ty) * (v10 - v00) + ty * (v11 - v01)) / g.resolution;
  s.gradient.y() = ((1 - tx) * (v01 - v00) + tx * (v11 - v10)) / g.resolution;
  return s;
}

// Samples the raster at every point seen from `pose` into `samples` and returns their sum (the
// score), in point order. The points are transformed exactly as Pose2::operator* does.
double SampleAll(const GridView& raster, std::span<const Eigen::Vector2d> points_base,
                 const Pose2& pose, std::vector<Sample>& samples) {
  const double c = std::cos(pose.theta()), s = std::sin(pose.theta());
  samples.resize(points_base.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < points_base.size(); ++i) {
    const Eigen::Vector2d& p = points_base[i];
    const Eigen::Vector2d world(pose.x() + c * p.x() - s * p.y(), pose.y() + s * p.x() + c * p.y());
    samples[i] = Interpolate(raster, world);
    sum += samples[i].value;
  }
  return sum;
}

double Square(double v) { return v * v; }

}  // namespace

std::vector<std::string> ScanRefinerOptions::Validate() const {
  Rules rules;
  rules.NonNegative("max_iterations", max_iterations)
      .Positive("max_step_m", max_step_m)
      .Positive("max_step_rad", max_step_rad)
      .NonNegative("converged_step_m", converged_step_m)
      .NonNegative("prior_sigma_xy_m", prior_sigma_xy_m)
      .NonNegative("prior_sigma_yaw_rad", prior_sigma_yaw_rad)
      .NonNegative("max_halvings", max_halvings);
  return rules.errors();
}

ScanRefiner::ScanRefiner(const ScanRefinerOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "ScanRefinerOptions");
}

double ScanRefiner::Score(const GridView& raster, std::span<const Eigen::Vector2d> points_base,
                          const Pose2& pose) {
  double sum = 0.0;
  for (const Eigen::Vector2d& p : points_base) sum += Interpolate(raster, pose * p).value;
  return sum;
}

double ScanRefiner::ValueAt(const GridView& raster, const Eigen::Vector2d& world) {
  return Interpolate(raster, world).value;
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
  // Each pose is sampled once: the samples that give a candidate's score also give the next
  // iteration's normal equations if the candidate is taken.
  thread_local std::vector<Sample> samples;
  RefineResult result{initial, SampleAll(raster, points_base, initial, samples),
                      prior_cost(initial), 0};
  if (!(max_value > 0.0f) || points_base.empty()) return result;
  const double scale = 1.0 / max_value;
  for (int it = 0; it < options_.max_iterations; ++it) {
    const Pose2& pose = result.pose;
    const double c = std::cos(pose.theta()), s = std::sin(pose.theta());
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    double residual_sum = 0.0;
    for (std::size_t i = 0; i < points_base.size(); ++i) {
      const Eigen::Vector2d& p = points_base[i];
      const Sample& m = samples[i];
      const double residual = 1.0 - scale * m.value;
      // d(world point)/d(theta) = R' p.
      const Eigen::Vector2d dtheta(-s * p.x() - c * p.y(), c * p.x() - s * p.y());
      const Eigen::Vector3d j(scale * m.gradient.x(), scale * m.gradient.y(),
                              scale * m.gradient.dot(dtheta));
      h += j * j.transpose();
      b += options_.maximise_score ? j : Eigen::Vector3d(j * residual);
      residual_sum += residual;
    }
    // The prior as extra residuals. Maximising the score, b is the gradient of scale x (score -
    // prior cost) and the prior's information enters scaled alike. On the residuals, the data's
    // gradient is sum r_i scale grad M_i where the score's is sum grad M_i: weighting the prior's
    // information by scale * mean(r_i) makes the two stationary points nearly agree.
    const double mean_residual = residual_sum / static_cast<double>(points_base.size());
    const Eigen::Vector3d w = scale * (options_.maximise_score ? 1.0 : mean_residual) * info;
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
    // The samples stay those of result.pose when every candidate is refused (the loop ends then).
    thread_local std::vector<Sample> candidate_samples;
    const int halvings = options_.maximise_score ? options_.max_halvings : 0;
    Pose2 candidate;
    double score = 0.0, cost = 0.0;
    bool better = false;
    for (int k = 0; k <= halvings && !better; ++k) {
      if (k > 0) step *= 0.5;
      candidate = Pose2(pose.x() + step.x(), pose.y() + step.y(), pose.theta() + step.z());
      score = SampleAll(raster, points_base, candidate, candidate_samples);
      cost = prior_cost(candidate);
      better = score - cost > result.score - result.prior_cost;
    }
    ++result.iterations;
    if (!better) break;
    samples.swap(candidate_samples);
    result.pose = candidate;
    result.score = score;
    result.prior_cost = cost;
    if (step.head<2>().norm() < options_.converged_step_m && std::abs(step.z()) < 1e-4) break;
  }
  return result;
}

}  // namespace slamrig::slam
