#pragma once

#include <sstream>
#include <string>
#include <string_view>

namespace slamrig {

/// The message of an options struct's Validate() for one broken rule, in Ceres's form:
/// "field = value; rule", e.g. RuleViolation("pf.num_particles", 0, "must be > 0") gives
/// "pf.num_particles = 0; must be > 0".
template <typename T>
std::string RuleViolation(std::string_view field, const T& value, std::string_view rule) {
  std::ostringstream s;
  s << field << " = " << value << "; " << rule;
  return s.str();
}

}  // namespace slamrig
