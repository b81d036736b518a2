#include "slam/eval/error_stats.h"

#include <algorithm>
#include <cmath>

namespace slamrig::slam {

ErrorStats ErrorStats::Of(std::vector<double> errors) {
  ErrorStats s;
  s.count = static_cast<int>(errors.size());
  if (errors.empty()) return s;
  double sum = 0.0, sum_sq = 0.0;
  for (const double e : errors) {
    sum += e;
    sum_sq += e * e;
    s.max = std::max(s.max, e);
  }
  const double n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  s.std_dev = std::sqrt(std::max(0.0, sum_sq / n - s.mean * s.mean));
  const std::size_t mid = errors.size() / 2;
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(mid), errors.end());
  s.median = errors[mid];
  if (errors.size() % 2 == 0) {
    s.median =
        0.5 * (s.median + *std::max_element(errors.begin(),
                                            errors.begin() + static_cast<std::ptrdiff_t>(mid)));
  }
  return s;
}

}  // namespace slamrig::slam
