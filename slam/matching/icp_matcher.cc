#include "slam/matching/icp_matcher.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
namespace {

// One source point paired with a reference point.
struct Pair {
  Eigen::Vector2d rotated;  // R(yaw) * source point (the translation not yet added)
  Eigen::Vector2d world;    // the source point in the reference frame
  std::uint32_t ref = 0;
  double residual = 0.0;  // |distance| (point-to-point) or |signed line distance|
};

double RobustWeight(const IcpOptions& options, double residual) {
  const double r = std::abs(residual);
  switch (options.kernel) {
    case RobustKernel::kNone:
      return 1.0;
    case RobustKernel::kHuber:
      return r <= options.kernel_scale_m ? 1.0 : options.kernel_scale_m / r;
    case RobustKernel::kCauchy: {
      const double u = r / options.kernel_scale_m;
      return 1.0 / (1.0 + u * u);
    }
  }
  return 1.0;
}

Eigen::Vector2d Perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

// The inverse of a symmetric positive semi-definite 3x3 matrix with its eigenvalues raised to
// 1e-9 of the largest (and to a tiny absolute floor), so it is finite even when degenerate.
Eigen::Matrix3d FlooredInverse(const Eigen::Matrix3d& h) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(h);
  Eigen::Vector3d values = eig.eigenvalues();
  const double floor = std::max(values.maxCoeff() * 1e-9, 1e-300);
  for (int i = 0; i < 3; ++i) values[i] = 1.0 / std::max(values[i], floor);
  return eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
}

// Gauss-Newton normal equations in (x, y, yaw) and the weighted squared residuals.
struct NormalEquations {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  double weighted_squares = 0.0;
  int num_residuals = 0;  // scalar residuals: 1 per pair (point-to-line) or 2 (point-to-point)
};

// The pairs of `source` seen from `pose`: nearest neighbours within the gate (with a normal, for
// point-to-line), then trimmed to the best trim_fraction (ties at the threshold kept), in source
// order. Returns the number that passed the gate, before trimming.
int Associate(const IcpMatcher& reference, std::span<const Eigen::Vector2d> source,
              const Pose2& pose, std::vector<Pair>* pairs, std::vector<double>* scratch) {
  const IcpOptions& options = reference.options();
  const double max_d2 =
      options.max_correspondence_distance_m * options.max_correspondence_distance_m;
  const auto& ref = reference.tree().points();
  pairs->clear();
  const double c = std::cos(pose.theta()), s = std::sin(pose.theta());
  for (const Eigen::Vector2d& p : source) {
    Pair pair;
    pair.rotated = Eigen::Vector2d(c * p.x() - s * p.y(), s * p.x() + c * p.y());
    pair.world = pair.rotated + pose.translation();
    double d2 = 0.0;
    if (!reference.tree().Nearest(pair.world, &pair.ref, &d2, max_d2)) continue;
    if (reference.has_normals()) {
      const Eigen::Vector2d n = reference.Normal(pair.ref);
      if (n.isZero()) continue;
      pair.residual = n.dot(pair.world - ref[pair.ref]);
    } else {
      pair.residual = std::sqrt(d2);
    }
    pairs->push_back(pair);
  }
  const int gated = static_cast<int>(pairs->size());
  if (options.trim_fraction < 1.0 && !pairs->empty()) {
    const auto keep = static_cast<std::size_t>(
        std::ceil(options.trim_fraction * static_cast<double>(pairs->size())));
    scratch->clear();
    for (const Pair& pair : *pairs) scratch->push_back(std::abs(pair.residual));
    std::nth_element(scratch->begin(), scratch->begin() + static_cast<std::ptrdiff_t>(keep - 1),
                     scratch->end());
    const double threshold = (*scratch)[keep - 1];
    std::erase_if(*pairs, [&](const Pair& pair) { return std::abs(pair.residual) > threshold; });
  }
  return gated;
}

// The robustly weighted normal equations of `pairs` (Jacobians with respect to (x, y, yaw) of the
// pose, d(R p)/d yaw = perp(R p)).
NormalEquations Accumulate(const IcpMatcher& reference, const std::vector<Pair>& pairs) {
  NormalEquations eq;
  const auto& ref = reference.tree().points();
  for (const Pair& pair : pairs) {
    const double w = RobustWeight(reference.options(), pair.residual);
    const Eigen::Vector2d dyaw = Perp(pair.rotated);
    if (reference.has_normals()) {
      const Eigen::Vector2d n = reference.Normal(pair.ref);
      const Eigen::Vector3d j(n.x(), n.y(), n.dot(dyaw));
      eq.h += w * j * j.transpose();
      eq.g += w * j * pair.residual;
      eq.weighted_squares += w * pair.residual * pair.residual;
      eq.num_residuals += 1;
    } else {
      const Eigen::Vector2d e = pair.world - ref[pair.ref];
      Eigen::Matrix<double, 2, 3> j;
      j << 1.0, 0.0, dyaw.x(), 0.0, 1.0, dyaw.y();
      eq.h += w * j.transpose() * j;
      eq.g += w * j.transpose() * e;
      eq.weighted_squares += w * e.squaredNorm();
      eq.num_residuals += 2;
    }
  }
  return eq;
}

// One Gauss-Newton step of the linearised point-to-line problem (Censi 2008), solved with
// the pseudo-inverse: no motion along directions the pairs do not constrain.
Pose2 PointToLineStep(const NormalEquations& eq, const Pose2& pose) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(eq.h);
  const Eigen::Vector3d values = eig.eigenvalues();
  const Eigen::Vector3d rhs = eig.eigenvectors().transpose() * (-eq.g);
  Eigen::Vector3d step_eig = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (values[i] > 0.0 && values[i] > 1e-9 * values.maxCoeff()) step_eig[i] = rhs[i] / values[i];
  }
  const Eigen::Vector3d step = eig.eigenvectors() * step_eig;
  return Pose2(pose.x() + step.x(), pose.y() + step.y(), pose.theta() + step.z());
}

// The weighted closed-form alignment of the pairs (Besl and McKay 1992; in 2D the SVD
// of the cross-covariance reduces to one atan2), applied on top of `pose`.
Pose2 PointToPointStep(const IcpMatcher& reference, const std::vector<Pair>& pairs,
                       const Pose2& pose) {
  const auto& ref = reference.tree().points();
  double sw = 0.0;
  Eigen::Vector2d mean_p = Eigen::Vector2d::Zero(), mean_q = Eigen::Vector2d::Zero();
  for (const Pair& pair : pairs) {
    const double w = RobustWeight(reference.options(), pair.residual);
    sw += w;
    mean_p += w * pair.world;
    mean_q += w * ref[pair.ref];
  }
  mean_p /= sw;
  mean_q /= sw;
  double sin_sum = 0.0, cos_sum = 0.0;
  for (const Pair& pair : pairs) {
    const double w = RobustWeight(reference.options(), pair.residual);
    const Eigen::Vector2d a = pair.world - mean_p, b = ref[pair.ref] - mean_q;
    sin_sum += w * (a.x() * b.y() - a.y() * b.x());
    cos_sum += w * (a.x() * b.x() + a.y() * b.y());
  }
  const double dyaw = std::atan2(sin_sum, cos_sum);
  const Eigen::Vector2d dt = mean_q - Pose2(0.0, 0.0, dyaw) * mean_p;
  return Pose2(dt.x(), dt.y(), dyaw) * pose;
}

}  // namespace

std::vector<std::string> IcpOptions::Validate() const {
  Rules rules;
  rules.AtLeast("max_iterations", max_iterations, 1)
      .NonNegative("converged_translation_m", converged_translation_m)
      .NonNegative("converged_rotation_rad", converged_rotation_rad)
      .Positive("max_correspondence_distance_m", max_correspondence_distance_m)
      .InUnitInterval("trim_fraction", trim_fraction)
      .Positive("kernel_scale_m", kernel_scale_m)
      .AtLeast("normal_neighbors", normal_neighbors, 3)
      .Positive("normal_radius_m", normal_radius_m)
      .AtLeast("min_correspondences", min_correspondences, 3);
  return rules.errors();
}

IcpMatcher::IcpMatcher(const IcpOptions& options, std::vector<Eigen::Vector2d> reference)
    : options_(options), tree_(std::move(reference)) {
  SLAMRIG_CHECK_VALID(options_, "IcpOptions");
  if (!has_normals()) return;
  normals_.assign(tree_.size(), Eigen::Vector2d::Zero());
  normal_state_ = std::vector<std::atomic<std::uint8_t>>(tree_.size());
}

Eigen::Vector2d IcpMatcher::Normal(std::uint32_t i) const {
  if (!has_normals()) return Eigen::Vector2d::Zero();
  SLAMRIG_CHECK(i < normals_.size(), "IcpMatcher::Normal: no such reference point");
  enum : std::uint8_t { kEmpty = 0, kWriting = 1, kReady = 2 };
  std::atomic<std::uint8_t>& state = normal_state_[i];
  if (state.load(std::memory_order_acquire) == kReady) return normals_[i];
  const Eigen::Vector2d normal = ComputeNormal(i);
  std::uint8_t expected = kEmpty;
  if (state.compare_exchange_strong(expected, kWriting, std::memory_order_acq_rel)) {
    normals_[i] = normal;
    state.store(kReady, std::memory_order_release);
  }
  return normal;
}

// The minor principal axis of the point's neighbourhood: its normal_neighbors nearest points
// within normal_radius_m (itself included); none for fewer than 3.
Eigen::Vector2d IcpMatcher::ComputeNormal(std::uint32_t i) const {
  const auto& points = tree_.points();
  std::vector<std::uint32_t> indices;
  std::vector<double> distances2;
  const double radius2 = options_.normal_radius_m * options_.normal_radius_m;
  tree_.KNearest(points[i], options_.normal_neighbors, &indices, &distances2);
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  int n = 0;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (distances2[k] > radius2) break;
    mean += points[indices[k]];
    ++n;
  }
  if (n < 3) return Eigen::Vector2d::Zero();
  mean /= n;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d d = points[indices[static_cast<std::size_t>(k)]] - mean;
    scatter += d * d.transpose();
  }
  // Closed-form eigenvector of the smaller eigenvalue of the symmetric 2x2 scatter matrix: the
  // major axis has angle 0.5 atan2(2 sxy, sxx - syy); the normal is perpendicular to it.
  const double major = 0.5 * std::atan2(2.0 * scatter(0, 1), scatter(0, 0) - scatter(1, 1));
  return Eigen::Vector2d(-std::sin(major), std::cos(major));
}

std::optional<MatchResult> IcpMatcher::Match(std::span<const Eigen::Vector2d> source,
                                             const Pose2& reference_from_source_guess) const {
  std::vector<Pair> pairs;
  pairs.reserve(source.size());
  std::vector<double> scratch;
  Pose2 pose = reference_from_source_guess;
  MatchResult result;
  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    Associate(*this, source, pose, &pairs, &scratch);
    if (static_cast<int>(pairs.size()) < options_.min_correspondences) return std::nullopt;
    result.iterations = iteration;
    const Pose2 next = has_normals() ? PointToLineStep(Accumulate(*this, pairs), pose)
                                     : PointToPointStep(*this, pairs, pose);
    const double moved = (next.translation() - pose.translation()).norm();
    const double turned = std::abs(NormalizeAngle(next.theta() - pose.theta()));
    pose = next;
    if (moved < options_.converged_translation_m && turned < options_.converged_rotation_rad) {
      result.converged = true;
      break;
    }
  }

  // Final pairs and covariance at the estimate.
  const int gated = Associate(*this, source, pose, &pairs, &scratch);
  if (static_cast<int>(pairs.size()) < options_.min_correspondences) return std::nullopt;
  const NormalEquations final_equations = Accumulate(*this, pairs);
  const double variance =
      final_equations.weighted_squares / std::max(1, final_equations.num_residuals - 3);
  result.pose = pose;
  result.covariance = variance * FlooredInverse(final_equations.h);
  result.correspondences = static_cast<int>(pairs.size());
  result.score = source.empty() ? 0.0 : gated / static_cast<double>(source.size());
  return result;
}

std::optional<MatchResult> IcpMatcher::MatchScans(const IcpOptions& options,
                                                  const ScanPointsOptions& points,
                                                  const LaserScan& reference,
                                                  const LaserScan& source,
                                                  const Pose2& reference_from_source_guess) {
  const IcpMatcher matcher(options, ScanToBasePoints(reference, points));
  const std::vector<Eigen::Vector2d> source_points = ScanToBasePoints(source, points);
  return matcher.Match(source_points, reference_from_source_guess);
}

}  // namespace slamrig::slam
