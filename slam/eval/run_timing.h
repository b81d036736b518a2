#pragma once

#include "slam/types/time.h"

namespace slamrig::slam {

/// How long a run took against how long its data lasts. Wall time is measured by the caller
/// (std::chrono::steady_clock) and never enters the estimator.
struct RunTiming {
  double wall_s = 0.0;  ///< processing time
  double data_s = 0.0;  ///< time span of the processed data (last scan - first scan)
  int scans = 0;

  /// data_s / wall_s: > 1 is faster than real time; 0 when nothing was timed.
  double RealTimeFactor() const { return wall_s > 0.0 ? data_s / wall_s : 0.0; }
  /// Mean wall time per scan, milliseconds.
  double MillisecondsPerScan() const { return scans > 0 ? 1e3 * wall_s / scans : 0.0; }
};

}  // namespace slamrig::slam
