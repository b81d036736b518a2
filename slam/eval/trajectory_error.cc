// ATE and RPE: Sturm, Engelhard, Endres, Burgard, Cremers, "A Benchmark for the Evaluation of
// RGB-D SLAM Systems", IROS 2012, Sec. V (Eqs. 1-5), restricted to SE(2).
#include "slam/eval/trajectory_error.h"

#include <cmath>

namespace slamrig::slam {

AteResult ComputeAte(const Trajectory& estimate, const Trajectory& reference,
                     const AssociationOptions& options) {
  const std::vector<PosePair> pairs = AssociatePoses(estimate, reference, options);
  AteResult result;
  result.reference_from_estimate = AlignSE2(pairs);
  std::vector<double> trans, rot;
  trans.reserve(pairs.size());
  rot.reserve(pairs.size());
  for (const PosePair& p : pairs) {
    const Pose2 aligned = result.reference_from_estimate * p.estimate;
    trans.push_back((aligned.translation() - p.reference.translation()).norm());
    rot.push_back(std::abs(NormalizeAngle(aligned.theta() - p.reference.theta())));
  }
  result.translation_m = ErrorStats::Of(std::move(trans));
  result.rotation_rad = ErrorStats::Of(std::move(rot));
  return result;
}

RpeResult ComputeRpe(const Trajectory& estimate, const Trajectory& reference, double distance_m,
                     const AssociationOptions& options) {
  const std::vector<PosePair> pairs = AssociatePoses(estimate, reference, options);
  // Reference path length at each pair, for distance-based spacing.
  std::vector<double> along(pairs.size(), 0.0);
  for (std::size_t i = 1; i < pairs.size(); ++i) {
    along[i] = along[i - 1] +
               (pairs[i].reference.translation() - pairs[i - 1].reference.translation()).norm();
  }
  RpeResult result;
  result.distance_m = distance_m;
  std::vector<double> trans, rot;
  std::size_t j = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (distance_m <= 0.0) {
      j = i + 1;
    } else {
      j = std::max(j, i + 1);
      while (j < pairs.size() && along[j] - along[i] < distance_m) ++j;
    }
    if (j >= pairs.size()) break;
    const Pose2 ref_delta = pairs[i].reference.Between(pairs[j].reference);
    const Pose2 est_delta = pairs[i].estimate.Between(pairs[j].estimate);
    const Pose2 error = ref_delta.Between(est_delta);
    trans.push_back(error.translation().norm());
    rot.push_back(std::abs(error.theta()));
  }
  result.translation_m = ErrorStats::Of(std::move(trans));
  result.rotation_rad = ErrorStats::Of(std::move(rot));
  return result;
}

}  // namespace slamrig::slam
