#pragma once

#include <vector>

namespace slamrig::slam {

/// Summary of a set of non-negative errors (metres or radians).
struct ErrorStats {
  int count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std_dev = 0.0;  ///< population standard deviation around `mean`
  double max = 0.0;

  /// Statistics of `errors` (all zero when empty).
  static ErrorStats Of(std::vector<double> errors);
};

}  // namespace slamrig::slam
