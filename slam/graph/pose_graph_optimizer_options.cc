#include "slam/graph/pose_graph_optimizer_options.h"

#include <cmath>
#include <utility>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> PoseGraphOptimizerOptions::Validate() const {
  const auto finite_positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  const auto finite_non_negative = [](double v) { return v >= 0.0 && std::isfinite(v); };
  Rules rules;
  rules.AtLeast("max_iterations", max_iterations, 1)
      .Require(finite_positive(robust_loss_scale), "robust_loss_scale", robust_loss_scale,
               "must be finite and > 0")
      .Require(finite_positive(initial_trust_region_radius), "initial_trust_region_radius",
               initial_trust_region_radius, "must be finite and > 0")
      .AtLeast("num_threads", num_threads, 1);
  for (const auto& [name, value] : {std::pair{"function_tolerance", function_tolerance},
                                    {"gradient_tolerance", gradient_tolerance},
                                    {"parameter_tolerance", parameter_tolerance}}) {
    rules.Require(finite_non_negative(value), name, value, "must be finite and >= 0");
  }
  return rules.errors();
}

const char* RobustLossName(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone:
      return "none";
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
    case RobustLoss::kSwitchable:
      return "switchable";
  }
  return "?";
}

const char* TrustRegionName(TrustRegion strategy) {
  return strategy == TrustRegion::kDogleg ? "dogleg" : "levenberg_marquardt";
}

}  // namespace slamrig::slam
