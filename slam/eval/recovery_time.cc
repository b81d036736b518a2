#include "slam/eval/recovery_time.h"

#include <algorithm>
#include <cmath>

namespace slamrig::slam {

double RecoveryTime(const std::vector<PosePair>& pairs, Time event, std::optional<Time> until,
                    double threshold_m) {
  bool any = false;
  // The last pair in the window over the bound: recovery is the pair after it.
  std::optional<std::size_t> last_bad;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const PosePair& p = pairs[i];
    if (p.time < event || (until && p.time >= *until)) continue;
    any = true;
    const double error = (p.estimate.translation() - p.reference.translation()).norm();
    // A NaN pose is not back on the truth either.
    if (!(error <= threshold_m)) last_bad = i;
  }
  if (!any) return NAN;
  if (!last_bad) return 0.0;
  // Recovered at the next pair inside the window, if there is one.
  for (std::size_t i = *last_bad + 1; i < pairs.size(); ++i) {
    const PosePair& p = pairs[i];
    if (p.time < event || (until && p.time >= *until)) continue;
    return SecondsBetween(p.time, event);
  }
  return NAN;
}

double WorstRecoveryTime(const std::vector<PosePair>& pairs, std::vector<Time> events,
                         double threshold_m) {
  if (events.empty()) return NAN;
  std::sort(events.begin(), events.end());
  double worst = 0.0;
  for (std::size_t k = 0; k < events.size(); ++k) {
    const std::optional<Time> until =
        k + 1 < events.size() ? std::optional<Time>(events[k + 1]) : std::nullopt;
    const double t = RecoveryTime(pairs, events[k], until, threshold_m);
    if (std::isnan(t)) return NAN;
    worst = std::max(worst, t);
  }
  return worst;
}

}  // namespace slamrig::slam
