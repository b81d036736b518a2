#pragma once

#include "slam/types/pose2.h"

namespace slamrig::slam {

/// An accepted loop closure between two scans of a run (indices in the order the estimator took
/// them): what a graph back end claims, and what slam/eval's loop-closure score checks.
struct LoopClosure {
  int from_scan = 0;  ///< the older scan (a past node)
  int to_scan = 0;    ///< the newer scan (the node that closed the loop)
  Pose2 measurement;  ///< pose of `to_scan`'s base frame in `from_scan`'s, as matched
};

}  // namespace slamrig::slam
