#include "slam/types/validation.h"

#include <charconv>

namespace slamrig {

std::string FormatNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string FormatFloat(float value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::vector<std::string> PrefixErrors(const std::string& prefix, std::vector<std::string> errors) {
  if (prefix.empty()) return errors;  // the root: keys are already whole paths
  for (auto& e : errors) e = prefix + "." + e;
  return errors;
}

void AppendErrors(std::vector<std::string>* errors, const std::vector<std::string>& more) {
  errors->insert(errors->end(), more.begin(), more.end());
}

}  // namespace slamrig
