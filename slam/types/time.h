#pragma once

#include <cmath>
#include <compare>
#include <cstdint>

namespace slamrig {

/// A point in time as integer nanoseconds since an arbitrary, source-specific epoch.
/// Integer ticks keep comparisons and differences exact (Cartographer's common::Time idea);
/// seconds as double are only for display and arithmetic at the edges.
struct Time {
  std::int64_t ns = 0;

  /// Rounds `seconds` to the nearest nanosecond.
  static constexpr Time FromSeconds(double seconds) {
    return Time{static_cast<std::int64_t>(std::llround(seconds * 1e9))};
  }
  static constexpr Time FromNanoseconds(std::int64_t nanoseconds) { return Time{nanoseconds}; }

  /// This time in seconds (loses precision past ~104 days at ns resolution).
  constexpr double seconds() const { return static_cast<double>(ns) * 1e-9; }

  friend constexpr auto operator<=>(Time, Time) = default;
};

/// Signed difference `a - b` in seconds.
constexpr double SecondsBetween(Time a, Time b) { return static_cast<double>(a.ns - b.ns) * 1e-9; }

/// `t` shifted by `seconds` (rounded to the nearest nanosecond).
constexpr Time AddSeconds(Time t, double seconds) {
  return Time{t.ns + static_cast<std::int64_t>(std::llround(seconds * 1e9))};
}

}  // namespace slamrig
