#pragma once

#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace slamrig {

/// `value` as Validate() messages print it: the shortest form that reads back exactly ("0.1",
/// "-3").
std::string FormatNumber(double value);
/// The same for a float: the shortest form that reads back as that float ("0.1", not
/// "0.10000000149011612").
std::string FormatFloat(float value);

/// `value` as a Validate() message prints it: numbers by FormatNumber (floating point) or in
/// full (integers), anything else as `operator<<` writes it (a text as it is).
template <typename T>
std::string FormatValue(const T& value) {
  if constexpr (std::is_floating_point_v<T>) {
    if constexpr (std::is_same_v<T, float>) {
      return FormatFloat(value);
    } else {
      return FormatNumber(static_cast<double>(value));
    }
  } else {
    std::ostringstream s;
    s << value;
    return s.str();
  }
}

/// The message of an options struct's Validate() for one broken rule, in Ceres's form:
/// "field = value; rule", e.g. RuleViolation("particles", 0, "must be > 0") gives
/// "particles = 0; must be > 0" (the value printed by FormatValue).
template <typename T>
std::string RuleViolation(std::string_view field, const T& value, std::string_view rule) {
  std::string message(field);
  message += " = ";
  message += FormatValue(value);
  message += "; ";
  message += rule;
  return message;
}

/// `prefix` + "." + each of `errors`: the key path of a nested options struct (an empty prefix,
/// the root, leaves them as they are).
std::vector<std::string> PrefixErrors(const std::string& prefix, std::vector<std::string> errors);

/// Appends `more` to `*errors`.
void AppendErrors(std::vector<std::string>* errors, const std::vector<std::string>& more);

/// Which ends of an interval belong to it: [lo, hi], (lo, hi], [lo, hi) or (lo, hi).
enum class Ends { kClosed, kOpenLow, kOpenHigh, kOpen };

/// The broken rules of an options struct, collected one line per rule in RuleViolation's form
/// ("field = value; rule"), numbers printed by FormatValue (values and bounds alike, so
/// "0.1" stays "0.1"). Every check fails on NaN. Typical use:
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
    return Require(value >= min, field, value, "must be >= " + FormatValue(min));
  }
  /// `value` > `min`.
  template <typename T>
  Rules& Above(std::string_view field, T value, T min) {
    return Require(value > min, field, value, "must be > " + FormatValue(min));
  }
  /// `value` in the interval from `lo` to `hi`, its ends closed unless `ends` says otherwise
  /// (Ends::kOpenLow: (lo, hi]).
  template <typename T>
  Rules& InRange(std::string_view field, T value, T lo, T hi, Ends ends = Ends::kClosed) {
    const bool open_low = ends == Ends::kOpenLow || ends == Ends::kOpen;
    const bool open_high = ends == Ends::kOpenHigh || ends == Ends::kOpen;
    const bool ok = (open_low ? value > lo : value >= lo) && (open_high ? value < hi : value <= hi);
    return Require(ok, field, value,
                   std::string("must be in ") + (open_low ? "(" : "[") + FormatValue(lo) + ", " +
                       FormatValue(hi) + (open_high ? ")" : "]"));
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
  /// A key that must be given: "field: required (what)" when `present` is false, e.g.
  /// Required(!module.empty(), "module", "the Python module to import").
  Rules& Required(bool present, std::string_view field, std::string_view what) {
    if (present) return *this;
    std::string message(field);
    message += ": required (";
    message += what;
    message += ")";
    return Add(std::move(message));
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
