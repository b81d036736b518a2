#pragma once

#include <optional>
#include <vector>

#include "slam/eval/pose_association.h"
#include "slam/types/time.h"

namespace slamrig::slam {

/// How long an estimate took to come back to the truth after an event that threw it off (a
/// kidnapping): the data time from `event` to the first pair from which on every pair before
/// `until` (the next event; none: the rest of the run) has a position error of at
/// most `threshold_m`. Measured from the truth, whatever the estimator says about itself, so it
/// scores any estimator alike. The pairs are compared as they stand (no alignment, as the final
/// error is): a kidnapped estimate is wrong in the truth's own frame.
///
/// 0 when the error never leaves the bound after the event; NaN when the estimate never gets back
/// within it, or there is no pair in [event, until).
double RecoveryTime(const std::vector<PosePair>& pairs, Time event, std::optional<Time> until,
                    double threshold_m);

/// The worst RecoveryTime over several events (each one's window ends at the next, in time
/// order); NaN when `events` is empty or any event is never recovered from.
double WorstRecoveryTime(const std::vector<PosePair>& pairs, std::vector<Time> events,
                         double threshold_m);

}  // namespace slamrig::slam
