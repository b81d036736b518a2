#include "slam/graph/pose_graph_optimizer_options.h"

#include <cmath>
#include <utility>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> PoseGraphOptimizerOptions::Validate() const {
  std::vector<std::string> errors;
  if (max_iterations < 1) {
    errors.push_back(RuleViolation("graph.max_iterations", max_iterations, "must be >= 1"));
  }
  if (!(robust_loss_scale > 0.0) || !std::isfinite(robust_loss_scale)) {
    errors.push_back(
        RuleViolation("graph.robust_loss_scale", robust_loss_scale, "must be finite and > 0"));
  }
  if (!(initial_trust_region_radius > 0.0) || !std::isfinite(initial_trust_region_radius)) {
    errors.push_back(RuleViolation("graph.initial_trust_region_radius", initial_trust_region_radius,
                                   "must be finite and > 0"));
  }
  if (num_threads < 1) {
    errors.push_back(RuleViolation("graph.num_threads", num_threads, "must be >= 1"));
  }
  const std::pair<const char*, double> tolerances[] = {
      {"graph.function_tolerance", function_tolerance},
      {"graph.gradient_tolerance", gradient_tolerance},
      {"graph.parameter_tolerance", parameter_tolerance}};
  for (const auto& [name, value] : tolerances) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      errors.push_back(RuleViolation(name, value, "must be finite and >= 0"));
    }
  }
  return errors;
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
