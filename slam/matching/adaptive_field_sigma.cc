#include "slam/matching/adaptive_field_sigma.h"

#include <algorithm>
#include <cmath>

#include "slam/matching/scan_refiner.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> AdaptiveSigmaOptions::Validate() const {
  Rules rules;
  rules.Positive("residual_factor", residual_factor)
      .Positive("min_m", min_m)
      .Require(max_m >= min_m, "max_m", max_m, "must be >= min_m")
      .Positive("window_m", window_m)
      .AtLeast("min_points", min_points, 1)
      .InUnitInterval("rate", rate)
      .NonNegative("warmup_updates", warmup_updates)
      .NonNegative("change_ratio", change_ratio);
  return rules.errors();
}

AdaptiveFieldSigma::AdaptiveFieldSigma(const AdaptiveSigmaOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "AdaptiveSigmaOptions");
}

std::optional<double> AdaptiveFieldSigma::MedianWallDistance(
    const LikelihoodField& field, std::span<const Eigen::Vector2d> points_base,
    const Pose2& pose) const {
  const GridView view = field.view();
  thread_local std::vector<double> distances;
  distances.clear();
  for (const Eigen::Vector2d& p : points_base) {
    const double d = field.Distance(ScanRefiner::ValueAt(view, pose * p));
    if (d <= options_.window_m) distances.push_back(d);
  }
  if (distances.size() < static_cast<std::size_t>(options_.min_points)) return std::nullopt;
  const auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return *middle;
}

std::optional<double> AdaptiveFieldSigma::Observe(double median_m, double sigma_in_use_m) {
  if (!options_.enabled) return std::nullopt;
  // The mean of the first 1 / rate medians, then an exponential average with that memory.
  ++updates_;
  median_m_ += std::max(options_.rate, 1.0 / updates_) * (median_m - median_m_);
  if (updates_ <= options_.warmup_updates) return std::nullopt;
  const double target =
      std::clamp(options_.residual_factor * median_m_, options_.min_m, options_.max_m);
  if (std::abs(target - sigma_in_use_m) <= options_.change_ratio * sigma_in_use_m) {
    return std::nullopt;
  }
  ++moves_;
  return target;
}

}  // namespace slamrig::slam
