#pragma once

#include <string>
#include <vector>

#include "slam/types/loop_closure.h"
#include "slam/types/pose2.h"

namespace slamrig::slam {

/// When a claimed loop closure counts as true, and what counts as a revisit for recall.
struct LoopClosureScoreOptions {
  double tolerance_m = 0.3;       ///< claimed vs reference relative translation, at most this ...
  double tolerance_rad = 0.1;     ///< ... and relative heading, at most this
  double revisit_radius_m = 1.0;  ///< a revisit: a reference pose this close to an earlier one ...
  double revisit_min_path_m = 10.0;  ///< ... that is at least this far back along the path
  /// Revisit scans closer than this along the path form one revisit episode (one chance to close).
  double episode_gap_m = 2.0;

  /// One message per broken rule ("tolerance_m = 0; must be > 0").
  std::vector<std::string> Validate() const;
};

/// Precision and recall of a run's loop closures against a reference trajectory.
struct LoopClosureScore {
  int closures = 0;                     ///< claimed
  int false_closures = 0;               ///< whose relative pose disagrees with the reference's
  double precision = 1.0;               ///< true / claimed (1 when none is claimed)
  int revisit_episodes = 0;             ///< stretches of the path that revisit an earlier place
  int recalled_episodes = 0;            ///< episodes with a true closure ending inside them
  double recall = 1.0;                  ///< recalled / episodes (1 when there is no revisit)
  std::vector<LoopClosure> false_ones;  ///< the false closures, in the given order
  std::vector<bool> is_true;            ///< per given closure
};

/// Scores `closures` (scan indices into `reference`, one reference pose per scan). A closure is
/// true when its measurement agrees with reference[from].Between(reference[to]) within the
/// tolerances. Closures with an index outside `reference` are false. Recall: the revisit scans
/// (within revisit_radius_m of a scan at least revisit_min_path_m earlier along the reference
/// path) are grouped into episodes (runs separated by less than episode_gap_m of path), and an
/// episode is recalled when a true closure's newer scan lies in its scan range.
LoopClosureScore ScoreLoopClosures(const std::vector<LoopClosure>& closures,
                                   const std::vector<Pose2>& reference,
                                   const LoopClosureScoreOptions& options = {});

}  // namespace slamrig::slam
