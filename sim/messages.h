#pragma once

#include <string>
#include <vector>

namespace slamrig::sim {

/// `value` as Validate() messages print it: shortest form that reads back exactly ("0.1", "-3").
std::string FormatNumber(double value);

/// `prefix` + "." + each of `errors`: the key path of a nested options struct.
std::vector<std::string> PrefixErrors(const std::string& prefix, std::vector<std::string> errors);

/// Appends `more` to `*errors`.
void AppendErrors(std::vector<std::string>* errors, const std::vector<std::string>& more);

}  // namespace slamrig::sim
