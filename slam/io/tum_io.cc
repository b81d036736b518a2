#include "slam/io/tum_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>

#include "slam/io/atomic_file.h"
#include "slam/io/line_reader.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// Whole seconds that fit Time's int64 nanoseconds with room for the fraction (about +-292 years).
constexpr std::int64_t kMaxStampSeconds = 9'223'372'035;

// Parses a decimal seconds stamp exactly to nanoseconds ("1298445274.541885123"), so unix-time
// stamps survive a round trip; other spellings (exponents) go through double. Stamps Time cannot
// hold (|t| > kMaxStampSeconds) are rejected like malformed ones.
std::optional<Time> ParseStamp(std::string_view text) {
  const std::size_t dot = text.find('.');
  const std::string_view whole = text.substr(0, dot);
  const std::string_view frac = dot == std::string_view::npos ? "" : text.substr(dot + 1);
  std::int64_t seconds = 0;
  const bool negative = !whole.empty() && whole.front() == '-';
  const auto [end, ec] = std::from_chars(whole.data(), whole.data() + whole.size(), seconds);
  const bool digits_only =
      std::all_of(frac.begin(), frac.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (ec == std::errc() && end == whole.data() + whole.size() && digits_only && frac.size() <= 9 &&
      !whole.empty()) {
    if (seconds > kMaxStampSeconds || seconds < -kMaxStampSeconds) return std::nullopt;
    std::int64_t nanos = 0;
    for (std::size_t i = 0; i < 9; ++i) nanos = nanos * 10 + (i < frac.size() ? frac[i] - '0' : 0);
    return Time::FromNanoseconds(seconds * 1'000'000'000 + (negative ? -nanos : nanos));
  }
  double value = 0.0;
  const auto [end2, ec2] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec2 != std::errc() || end2 != text.data() + text.size() || !std::isfinite(value) ||
      std::abs(value) > static_cast<double>(kMaxStampSeconds)) {
    return std::nullopt;
  }
  return Time::FromSeconds(value);
}

}  // namespace

std::string FormatTum(const Trajectory& trajectory) {
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (const StampedPose& p : trajectory.poses()) {
    const double half = 0.5 * p.pose.theta();
    // Seconds with nanosecond digits; %.17g for positions so that files round-trip exactly.
    const std::int64_t whole = p.time.ns / 1'000'000'000;
    std::int64_t frac = p.time.ns % 1'000'000'000;
    const char* sign = (p.time.ns < 0 && (whole == 0)) ? "-" : "";
    if (frac < 0) frac = -frac;
    std::snprintf(line, sizeof(line), "%s%lld.%09lld %.17g %.17g 0 0 0 %.17g %.17g\n", sign,
                  static_cast<long long>(whole), static_cast<long long>(frac), p.pose.x(),
                  p.pose.y(), std::sin(half), std::cos(half));
    out += line;
  }
  return out;
}

void WriteTum(const std::string& path, const Trajectory& trajectory) {
  WriteFileAtomically(path, FormatTum(trajectory));
}

Trajectory ReadTum(const std::string& path, bool in_time_order) {
  LineReader reader(path);
  Trajectory trajectory;
  std::string_view line;
  static const char* kFields[] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  while (reader.Next(&line)) {
    const std::string where = path + ":" + std::to_string(reader.line_number()) + ": ";
    std::size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i == line.size() || line[i] == '#') continue;
    double v[8];
    std::optional<Time> stamp;
    int n = 0;
    while (i < line.size()) {
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != ',') ++i;
      if (i > start) {
        if (n == 8) throw ParseError(where + "expected 8 fields (t x y z qx qy qz qw), found more");
        const std::string_view token = line.substr(start, i - start);
        bool ok = true;
        if (n == 0) {
          stamp = ParseStamp(token);
          ok = stamp.has_value();
        } else {
          const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v[n]);
          ok = ec == std::errc() && end == token.data() + token.size() && std::isfinite(v[n]);
        }
        if (!ok) {
          throw ParseError(where + kFields[n] +
                           (n == 0 ? ": expected seconds within +-9.2e9, got '"
                                   : ": expected a finite number, got '") +
                           std::string(line.substr(start, i - start)) + "'");
        }
        ++n;
      }
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == ',')) ++i;
    }
    if (n != 8) {
      throw ParseError(where + "expected 8 fields (t x y z qx qy qz qw), found " +
                       std::to_string(n));
    }
    const double qx = v[4], qy = v[5], qz = v[6], qw = v[7];
    const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
    if (std::abs(norm - 1.0) > 1e-3) {
      throw ParseError(where + "quaternion: norm " + std::to_string(norm) + ", expected 1");
    }
    if (std::hypot(qx, qy) > 1e-3 * norm) {
      throw ParseError(where + "quaternion: rotation leaves the plane (qx, qy not 0)");
    }
    const Time t = *stamp;
    if (in_time_order && !trajectory.empty() && t < trajectory.poses().back().time) {
      throw ParseError(where + "timestamp: " + std::to_string(t.seconds()) +
                       " is earlier than the line before");
    }
    trajectory.Append(t, Pose2(v[1], v[2], 2.0 * std::atan2(qz, qw)));
  }
  return trajectory;
}

}  // namespace slamrig::slam
