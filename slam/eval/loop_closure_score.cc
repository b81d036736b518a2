#include "slam/eval/loop_closure_score.h"

#include <cmath>
#include <cstddef>

#include "slam/types/validation.h"

namespace slamrig::slam {

std::vector<std::string> LoopClosureScoreOptions::Validate() const {
  Rules rules;
  rules.Positive("tolerance_m", tolerance_m)
      .Positive("tolerance_rad", tolerance_rad)
      .Positive("revisit_radius_m", revisit_radius_m)
      .Positive("revisit_min_path_m", revisit_min_path_m)
      .Positive("episode_gap_m", episode_gap_m);
  return rules.errors();
}

LoopClosureScore ScoreLoopClosures(const std::vector<LoopClosure>& closures,
                                   const std::vector<Pose2>& reference,
                                   const LoopClosureScoreOptions& options) {
  LoopClosureScore score;
  const int n = static_cast<int>(reference.size());
  score.closures = static_cast<int>(closures.size());
  for (const LoopClosure& c : closures) {
    bool ok = c.from_scan >= 0 && c.to_scan >= 0 && c.from_scan < n && c.to_scan < n;
    if (ok) {
      const Pose2 truth = reference[c.from_scan].Between(reference[c.to_scan]);
      const Pose2 error = truth.Between(c.measurement);
      ok = error.translation().norm() <= options.tolerance_m &&
           std::abs(error.theta()) <= options.tolerance_rad;
    }
    score.is_true.push_back(ok);
    if (!ok) {
      ++score.false_closures;
      score.false_ones.push_back(c);
    }
  }
  if (score.closures > 0) {
    score.precision = static_cast<double>(score.closures - score.false_closures) / score.closures;
  }

  // Path length at each scan, and the revisit scans.
  std::vector<double> path(reference.size(), 0.0);
  for (int i = 1; i < n; ++i) {
    path[i] = path[i - 1] + (reference[i].translation() - reference[i - 1].translation()).norm();
  }
  std::vector<int> revisits;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < i && path[i] - path[j] >= options.revisit_min_path_m; ++j) {
      if ((reference[i].translation() - reference[j].translation()).norm() <=
          options.revisit_radius_m) {
        revisits.push_back(i);
        break;
      }
    }
  }
  // Episodes: [first, last] scan ranges.
  std::vector<std::pair<int, int>> episodes;
  for (const int i : revisits) {
    if (episodes.empty() || path[i] - path[episodes.back().second] >= options.episode_gap_m) {
      episodes.emplace_back(i, i);
    } else {
      episodes.back().second = i;
    }
  }
  score.revisit_episodes = static_cast<int>(episodes.size());
  for (const auto& [first, last] : episodes) {
    for (std::size_t k = 0; k < closures.size(); ++k) {
      if (score.is_true[k] && closures[k].to_scan >= first && closures[k].to_scan <= last) {
        ++score.recalled_episodes;
        break;
      }
    }
  }
  if (score.revisit_episodes > 0) {
    score.recall = static_cast<double>(score.recalled_episodes) / score.revisit_episodes;
  }
  return score;
}

}  // namespace slamrig::slam
