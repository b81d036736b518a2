#pragma once

#include <sstream>
#include <string>
#include <string_view>
#include <utility>
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

/// The broken rules of an options struct, collected one line per rule in RuleViolation's form
/// ("field = value; rule"). Every check fails on NaN. Typical use:
///
///   Rules rules;
///   rules.Positive("resolution_m", resolution_m).AtLeast("beams", beams, 1);
///   rules.Nested("correlation", correlation.Validate());
///   return rules.errors();
class Rules {
 public:
  /// `value` > 0.
  template <typename T>
  Rules& Positive(std::string_view field, T value) {
    return Require(value > T{0}, field, value, "must be > 0");
  }
  /// `value` >= 0.
  template <typename T>
  Rules& NonNegative(std::string_view field, T value) {
    return Require(value >= T{0}, field, value, "must be >= 0");
  }
  /// `value` >= `min`.
  template <typename T>
  Rules& AtLeast(std::string_view field, T value, T min) {
    if (value >= min) return *this;
    std::ostringstream rule;
    rule << "must be >= " << min;
    return Add(RuleViolation(field, value, rule.str()));
  }
  /// `value` in the closed interval [lo, hi].
  template <typename T>
  Rules& InRange(std::string_view field, T value, T lo, T hi) {
    if (value >= lo && value <= hi) return *this;
    std::ostringstream rule;
    rule << "must be in [" << lo << ", " << hi << "]";
    return Add(RuleViolation(field, value, rule.str()));
  }
  /// `value` in (0, 1]: a rate or a ratio that cannot be zero.
  Rules& InUnitInterval(std::string_view field, double value) {
    return Require(value > 0.0 && value <= 1.0, field, value, "must be in (0, 1]");
  }
  /// `value` in [0, 1]: a probability or a fraction.
  Rules& Fraction(std::string_view field, double value) {
    return Require(value >= 0.0 && value <= 1.0, field, value, "must be in [0, 1]");
  }
  /// Any other rule: `ok` says whether it holds, `rule` is its text ("must be > min_range_m").
  template <typename T>
  Rules& Require(bool ok, std::string_view field, const T& value, std::string_view rule) {
    if (ok) return *this;
    return Add(RuleViolation(field, value, rule));
  }
  /// The errors of a nested options struct, under the key `prefix`.
  Rules& Nested(const std::string& prefix, std::vector<std::string> errors) {
    AppendErrors(&errors_, PrefixErrors(prefix, std::move(errors)));
    return *this;
  }
  /// A message already in the "field = value; rule" form.
  Rules& Add(std::string message) {
    errors_.push_back(std::move(message));
    return *this;
  }

  const std::vector<std::string>& errors() const { return errors_; }

 private:
  std::vector<std::string> errors_;
};

}  // namespace slamrig
