#pragma once

#include <cstdio>
#include <string>

namespace slamrig {

/// `v` with `digits` decimals ("%.*f"): Fixed(0.12345, 3) is "0.123".
inline std::string Fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, v);
  return buffer;
}

/// `v` in a printf `format` with one double conversion: Number("%.6g", 1234567.0) is "1.23457e+06".
inline std::string Number(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

}  // namespace slamrig
