#pragma once

#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace slamrig {

/// `value` as Validate() messages print it: the shortest form that reads back exactly ("0.1",
/// "-3").
std::string FormatNumber(double value);

/// The message of an options struct's Validate() for one broken rule, in Ceres's form:
/// "field = value; rule", e.g. RuleViolation("particles", 0, "must be > 0") gives
/// "particles = 0; must be > 0".
template <typename T>
std::string RuleViolation(std::string_view field, const T& value, std::string_view rule) {
  std::ostringstream s;
  s << field << " = " << value << "; " << rule;
  return s.str();
}

/// `prefix` + "." + each of `errors`: the key path of a nested options struct (an empty prefix,
/// the root, leaves them as they are).
std::vector<std::string> PrefixErrors(const std::string& prefix, std::vector<std::string> errors);

/// Appends `more` to `*errors`.
void AppendErrors(std::vector<std::string>* errors, const std::vector<std::string>& more);

}  // namespace slamrig
