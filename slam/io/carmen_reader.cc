#include "slam/io/carmen_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string_view>

#include "slam/io/dataset.h"
#include "slam/io/line_reader.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// A problem with one field of one line; turned into a ParseError or a counted skip by the caller.
struct LineError {
  std::string field;
  std::string problem;
};

class Fields {
 public:
  explicit Fields(std::string_view line) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > start) tokens_.push_back(line.substr(start, i - start));
    }
  }
  std::size_t size() const { return tokens_.size(); }
  std::string_view operator[](std::size_t i) const { return tokens_[i]; }

  void ExpectCount(std::size_t expected, const std::string& what) const {
    if (tokens_.size() != expected) {
      throw LineError{"line", "expected " + std::to_string(expected) + " fields" + what +
                                  ", found " + std::to_string(tokens_.size()) +
                                  (tokens_.size() < expected ? " (truncated line?)" : "")};
    }
  }
  void ExpectAtLeast(std::size_t expected, const std::string& what) const {
    if (tokens_.size() < expected) {
      throw LineError{"line", "expected at least " + std::to_string(expected) + " fields" + what +
                                  ", found " + std::to_string(tokens_.size()) +
                                  " (truncated line?)"};
    }
  }

  double Number(std::size_t i, const std::string& field) const {
    const std::string_view t = tokens_[i];
    double value = 0.0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (ec != std::errc() || end != t.data() + t.size()) {
      throw LineError{field, "expected a number, got '" + std::string(t) + "'"};
    }
    if (!std::isfinite(value)) {
      throw LineError{field, "not a finite number: '" + std::string(t) + "'"};
    }
    return value;
  }

  // A laser message's beam count: a whole number in [1, kMaxBeams] (a scan without beams is
  // malformed: nothing downstream can use it).
  int BeamCount(std::size_t i, int max_value) const {
    const int n = Count(i, "num_readings", max_value);
    if (n == 0) throw LineError{"num_readings", "a laser message needs at least one reading"};
    return n;
  }

  int Count(std::size_t i, const std::string& field, int max_value) const {
    const std::string_view t = tokens_[i];
    int value = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (ec != std::errc() || end != t.data() + t.size()) {
      throw LineError{field, "expected a whole number, got '" + std::string(t) + "'"};
    }
    if (value < 0 || value > max_value) {
      throw LineError{
          field, std::to_string(value) + " is out of range [0, " + std::to_string(max_value) + "]"};
    }
    return value;
  }

  Pose2 PoseAt(std::size_t i, const std::string& field) const {
    return Pose2(Number(i, field + ".x"), Number(i + 1, field + ".y"),
                 Number(i + 2, field + ".theta"));
  }

  // Parsed straight into floats (what a scan holds), so the shortest float text slamrig writes
  // reads back bit for bit; the field name is only built for an error.
  std::vector<float> Ranges(std::size_t first, int n) const {
    std::vector<float> ranges(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      const std::string_view t = tokens_[first + static_cast<std::size_t>(k)];
      float r = 0.0f;
      const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), r);
      if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(r) || r < 0.0f) {
        const std::string field = "range[" + std::to_string(k) + "]";
        Number(first + static_cast<std::size_t>(k), field);  // names a non-number or NaN
        if (ec == std::errc::result_out_of_range) {
          throw LineError{field, "out of range for a float: '" + std::string(t) + "'"};
        }
        throw LineError{field, "negative range " + std::string(t)};
      }
      ranges[static_cast<std::size_t>(k)] = r;
    }
    return ranges;
  }

 private:
  std::vector<std::string_view> tokens_;
};

constexpr int kMaxBeams = 100000;
constexpr double kDeg = std::numbers::pi / 180.0;

// Control characters anywhere, or a non-ASCII message type: not a CARMEN text line.
bool IsBinary(std::string_view line) {
  const bool control = std::any_of(line.begin(), line.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return (u < 0x20 && c != '\t') || u == 0x7f;
  });
  const std::string_view type = line.substr(0, line.find_first_of(" \t"));
  return control || std::any_of(type.begin(), type.end(),
                                [](char c) { return static_cast<unsigned char>(c) >= 0x80; });
}

// The message types ParseLine reads.
bool IsKnownMessage(std::string_view type) {
  return type == "FLASER" || type == "RLASER" || type == "ROBOTLASER1" || type == "ROBOTLASER2" ||
         (type.starts_with("RAWLASER") && type.size() == 9 && type[8] >= '1' && type[8] <= '4') ||
         type == "ODOM" || type == "TRUEPOS" || type == "PARAM";
}

// A message before times are fixed up: which list it went to and its raw stamp.
struct Stamped {
  enum class Kind { kScan, kOdometry, kTruth } kind;
  std::size_t index;
  double stamp_s;
  int line;
};

class CarmenParser {
 public:
  CarmenParser(const std::string& path, const CarmenReadOptions& options) : options_(options) {
    log_.path = path;
  }

  void ParseLine(std::string_view line, int line_number) {
    Fields f(line);
    if (f.size() == 0 || f[0].front() == '#') return;
    const std::string type(f[0]);
    if (!IsKnownMessage(type)) {
      ++log_.stats.unknown_messages[type];
      return;
    }
    if (type == "FLASER" || type == "RLASER") {
      ParseOldLaser(f, type, line_number);
    } else if (type == "ROBOTLASER1" || type == "ROBOTLASER2") {
      ParseRobotLaser(f, line_number);
    } else if (type.starts_with("RAWLASER")) {
      ParseRawLaser(f, line_number);
    } else if (type == "ODOM") {
      ParseOdometry(f, line_number);
    } else if (type == "TRUEPOS") {
      f.ExpectCount(10, " for TRUEPOS");
      GroundTruthPose truth;
      truth.map_from_base = f.PoseAt(1, "true");
      f.PoseAt(4, "odom");
      Record(Stamped::Kind::kTruth, log_.true_poses.size(), f.Number(7, "ipc_timestamp"),
             line_number);
      log_.true_poses.push_back(truth);
    } else {
      f.ExpectAtLeast(3, " for PARAM");
      log_.params[std::string(f[1])] = std::string(f[2]);
    }
    ++log_.stats.messages[type];
    last_was_laser_ = type != "ODOM" && type != "PARAM" && type != "TRUEPOS";
  }

  CarmenLog Finish() {
    ApplyParams();
    FixTimes();
    return std::move(log_);
  }

  CarmenLog& log() { return log_; }

 private:
  void Record(Stamped::Kind kind, std::size_t index, double stamp, int line) {
    stamped_.push_back({kind, index, stamp, line});
  }

  void ParseOldLaser(const Fields& f, const std::string& type, int line_number) {
    f.ExpectAtLeast(2, " for " + type);
    const int n = f.BeamCount(1, kMaxBeams);
    f.ExpectCount(static_cast<std::size_t>(n) + 11,
                  " for " + type + " with " + std::to_string(n) + " readings");
    CarmenScan s;
    s.scan.ranges_m = f.Ranges(2, n);
    const std::size_t p = 2 + static_cast<std::size_t>(n);
    s.logged_pose = f.PoseAt(p, "pose");
    s.odom_pose = f.PoseAt(p + 3, "odom");
    s.line = line_number;
    s.scan.angle_min_rad = -90.0 * kDeg;
    s.scan.angle_increment_rad =
        n > 1 ? (n % 2 == 0 ? 180.0 * kDeg / n : 180.0 * kDeg / (n - 1)) : 0.0;
    s.scan.range_min_m = 1e-3;
    if (type == "RLASER") s.scan.base_from_laser = Pose2(0.0, 0.0, std::numbers::pi);
    const double stamp = f.Number(p + 6, "ipc_timestamp");  // before anything is recorded
    rear_.push_back(type == "RLASER");
    Record(Stamped::Kind::kScan, log_.scans.size(), stamp, line_number);
    log_.scans.push_back(std::move(s));
  }

  // Shared layout of ROBOTLASER1 and RAWLASERx up to the remissions.
  std::size_t ParseLaserConfig(const Fields& f, const std::string& type, CarmenScan* s) {
    f.ExpectAtLeast(10, " for " + type);
    s->scan.angle_min_rad = f.Number(2, "start_angle");
    f.Number(3, "field_of_view");
    s->scan.angle_increment_rad = f.Number(4, "angular_resolution");
    s->scan.range_max_m = f.Number(5, "maximum_range");
    s->scan.range_min_m = 1e-3;
    const int n = f.BeamCount(8, kMaxBeams);
    f.ExpectAtLeast(10 + static_cast<std::size_t>(n),
                    " for " + type + " with " + std::to_string(n) + " readings");
    s->scan.ranges_m = f.Ranges(9, n);
    const std::size_t remissions_at = 9 + static_cast<std::size_t>(n);
    const int m = f.Count(remissions_at, "num_remissions", kMaxBeams);
    return remissions_at + 1 + static_cast<std::size_t>(m);
  }

  void ParseRobotLaser(const Fields& f, int line_number) {
    CarmenScan s;
    const std::size_t p = ParseLaserConfig(f, "ROBOTLASER1", &s);
    f.ExpectCount(p + 14,
                  " for ROBOTLASER1 with " + std::to_string(s.scan.ranges_m.size()) + " readings");
    const Pose2 world_from_laser = f.PoseAt(p, "laser_pose");
    s.logged_pose = f.PoseAt(p + 3, "robot_pose");
    s.odom_pose = s.logged_pose;
    s.scan.base_from_laser = s.logged_pose.Inverse() * world_from_laser;
    for (std::size_t k = p + 6; k < p + 11; ++k) f.Number(k, "robot_state");
    const double stamp = f.Number(p + 11, "ipc_timestamp");  // before anything is recorded
    s.line = line_number;
    rear_.push_back(false);
    explicit_max_.push_back(log_.scans.size());
    Record(Stamped::Kind::kScan, log_.scans.size(), stamp, line_number);
    log_.scans.push_back(std::move(s));
  }

  void ParseRawLaser(const Fields& f, int line_number) {
    CarmenScan s;
    const std::size_t p = ParseLaserConfig(f, std::string(f[0]), &s);
    f.ExpectCount(p + 3, " for " + std::string(f[0]));
    s.has_pose = false;
    const double stamp = f.Number(p, "ipc_timestamp");  // before anything is recorded
    s.line = line_number;
    rear_.push_back(false);
    explicit_max_.push_back(log_.scans.size());
    Record(Stamped::Kind::kScan, log_.scans.size(), stamp, line_number);
    log_.scans.push_back(std::move(s));
  }

  void ParseOdometry(const Fields& f, int line_number) {
    f.ExpectCount(10, " for ODOM");
    const Pose2 pose = f.PoseAt(1, "pose");
    for (std::size_t k = 4; k < 7; ++k) f.Number(k, k == 4 ? "tv" : k == 5 ? "rv" : "accel");
    const double stamp = f.Number(7, "ipc_timestamp");
    // GMapping's corrected logs echo each scan's corrected pose as the ODOM line right after
    // it. Recognised by position and content: most echoes have stamp 0, but some carry junk
    // stamps (1e-42, 1.7e-153, ... on intel), so the stamp alone does not tell. A stamp at or
    // after the scan's keeps a raw log's ODOM of a robot standing still from looking like one.
    if (last_was_laser_ && !log_.scans.empty() && log_.scans.back().has_pose &&
        (stamp == 0.0 || stamp < stamped_.back().stamp_s)) {
      const Pose2 d = log_.scans.back().logged_pose.Between(pose);
      if (std::abs(d.x()) < 1e-4 && std::abs(d.y()) < 1e-4 && std::abs(d.theta()) < 1e-4) {
        log_.is_corrected = true;
        ++log_.stats.skipped["GMapping echo ODOM (the scan's corrected pose)"];
        throw Skip{};
      }
    }
    CarmenOdometry o;
    o.odometry.odom_from_base = pose;
    o.line = line_number;
    Record(Stamped::Kind::kOdometry, log_.odometry.size(), stamp, line_number);
    log_.odometry.push_back(o);
  }

  void ApplyParams() {
    auto param = [&](const std::string& key) -> std::optional<double> {
      const auto it = log_.params.find(key);
      if (it == log_.params.end()) return std::nullopt;
      double v = 0;
      const auto [end, ec] =
          std::from_chars(it->second.data(), it->second.data() + it->second.size(), v);
      if (ec != std::errc() || !std::isfinite(v)) {
        throw ParseError(log_.path + ": PARAM " + key + ": expected a number, got '" + it->second +
                         "'");
      }
      return v;
    };
    const double front_offset = param("robot_frontlaser_offset").value_or(0.0);
    const double rear_offset = param("robot_rearlaser_offset").value_or(0.0);
    const auto resolution_deg = param("laser_front_laser_resolution");

    // The range that means "no return": a PARAM if present, else a saturation value that recurs
    // in the data (ACES: 50.0, Intel: 81.83), capped by the no-return code threshold.
    std::optional<double> max_range = param("robot_front_laser_max");
    if (!max_range) {
      float top = 0.0f;
      std::size_t total = 0;
      for (std::size_t i = 0; i < log_.scans.size(); ++i) {
        if (IsExplicit(i)) continue;
        for (const float r : log_.scans[i].scan.ranges_m) top = std::max(top, r);
        total += log_.scans[i].scan.ranges_m.size();
      }
      std::size_t at_top = 0;
      for (std::size_t i = 0; i < log_.scans.size(); ++i) {
        if (IsExplicit(i)) continue;
        for (const float r : log_.scans[i].scan.ranges_m) at_top += r >= top - 1e-3f;
      }
      if (total > 0 && at_top * 200 >= total) {
        max_range = top;
        log_.notes.push_back(
            "readings of " + std::to_string(top).substr(0, 6) + " m (" +
            std::to_string(100.0 * static_cast<double>(at_top) / static_cast<double>(total))
                .substr(0, 4) +
            " % of beams) taken as the scanner's no-return value");
      }
    }
    const double range_max =
        std::min(max_range.value_or(options_.no_return_range_m), options_.no_return_range_m);
    // Written by slamrig's simulator: what ROBOTLASER1 has no field for.
    const auto time_increment = param("laser_time_increment_s");
    const auto range_min = param("laser_range_min_m");
    for (std::size_t i = 0; i < log_.scans.size(); ++i) {
      LaserScan& scan = log_.scans[i].scan;
      if (time_increment) scan.time_increment_s = *time_increment;
      if (range_min) scan.range_min_m = *range_min;
      if (IsExplicit(i)) {
        scan.range_max_m = std::min(scan.range_max_m, options_.no_return_range_m);
        continue;
      }
      scan.range_max_m = range_max;
      if (resolution_deg) scan.angle_increment_rad = *resolution_deg * kDeg;
      const double offset = rear_[i] ? rear_offset : front_offset;
      scan.base_from_laser =
          Pose2(offset * (rear_[i] ? -1.0 : 1.0), 0.0, scan.base_from_laser.theta());
    }
  }

  bool IsExplicit(std::size_t scan_index) const {
    return std::binary_search(explicit_max_.begin(), explicit_max_.end(), scan_index);
  }

  // Stamps: keep them when they are real, else synthesize from file order; never let time go
  // backwards (messages are processed in file order, as the logger wrote them).
  void FixTimes() {
    std::size_t zero = 0, increasing = 0;
    for (std::size_t i = 0; i < stamped_.size(); ++i) {
      zero += stamped_[i].stamp_s == 0.0;
      if (i > 0) increasing += stamped_[i].stamp_s > stamped_[i - 1].stamp_s;
    }
    const std::size_t n = stamped_.size();
    // Real logs advance their clock on most messages; %g-printed unix times or zeros do not.
    log_.timestamps_usable = n < 2 || (zero * 10 < n && increasing * 4 >= n);
    if (!log_.timestamps_usable && n > 0) {
      log_.notes.push_back("timestamps unusable (" + std::to_string(zero) + " of " +
                           std::to_string(n) + " zero, " + std::to_string(increasing) +
                           " increasing); times synthesized from file order, 1 ms per line");
    }
    Time previous = Time::FromNanoseconds(std::numeric_limits<std::int64_t>::min());
    for (const Stamped& s : stamped_) {
      Time t = log_.timestamps_usable
                   ? Time::FromSeconds(s.stamp_s)
                   : Time::FromNanoseconds(static_cast<std::int64_t>(s.line) * 1'000'000);
      // A stamp earlier than its predecessor's stays as it is (the message stays in file order).
      if (t < previous) ++log_.stats.out_of_order_times;
      previous = std::max(previous, t);
      switch (s.kind) {
        case Stamped::Kind::kScan:
          log_.scans[s.index].scan.time = t;
          break;
        case Stamped::Kind::kOdometry:
          log_.odometry[s.index].odometry.time = t;
          break;
        case Stamped::Kind::kTruth:
          log_.true_poses[s.index].time = t;
          break;
      }
    }
    if (log_.stats.out_of_order_times > 0) {
      log_.notes.push_back(std::to_string(log_.stats.out_of_order_times) +
                           " stamps earlier than the message before them; kept in file order, each "
                           "with its own stamp");
    }
  }

 public:
  struct Skip {};

 private:
  CarmenReadOptions options_;
  CarmenLog log_;
  std::vector<Stamped> stamped_;
  std::vector<bool> rear_;                 // per scan: RLASER
  std::vector<std::size_t> explicit_max_;  // scans whose line carries its own max range
  bool last_was_laser_ = false;
};

}  // namespace

CarmenLog ReadCarmenLog(const std::string& path, const CarmenReadOptions& options) {
  LineReader reader(path, !options.strict);
  CarmenParser parser(path, options);
  std::string_view line;
  int lines = 0;
  int cut_line = 0;  // the unfinished last line left out, if any
  while (reader.Next(&line)) {
    ++lines;
    const int number = reader.line_number();
    // A last line without its end of line is where a log cut short stops, unless it is a whole
    // message (a log without a final newline): a message's fields are counted, so one cut short
    // fails to parse, and only a cut in the unread logger stamp at its end goes unnoticed.
    // PARAM lines have no fixed count. A binary last line stays an error: a cut leaves text.
    const bool unfinished = !options.strict && !reader.terminated();
    if (unfinished && !IsBinary(line)) {
      const Fields f(line);
      const std::string_view type = f.size() > 0 ? f[0] : std::string_view("#");
      if (type.front() != '#' && (reader.cut() || !IsKnownMessage(type) || type == "PARAM")) {
        cut_line = number;
        break;
      }
    }
    auto fail = [&](const std::string& field, const std::string& problem, const std::string& kind) {
      if (!options.lenient) {
        throw ParseError(path + ":" + std::to_string(number) + ": " + field + ": " + problem);
      }
      ++parser.log().stats.skipped[kind];
    };
    if (IsBinary(line)) {
      fail("line", "binary data, not a CARMEN text log", "binary line");
      continue;
    }
    try {
      parser.ParseLine(line, number);
    } catch (const LineError& e) {
      if (unfinished) {
        cut_line = number;
        break;
      }
      const std::string type_name{Fields(line)[0]};
      fail(type_name + " " + e.field, e.problem, "malformed " + type_name);
    } catch (const CarmenParser::Skip&) {
    }
  }
  if (lines == 0) throw ParseError(path + ": empty file");
  CarmenLog log = parser.Finish();
  if (log.stats.messages.empty()) {
    throw ParseError(path + ": no CARMEN messages (FLASER, ROBOTLASER1, ODOM, ...) in " +
                     std::to_string(lines) + " lines" +
                     (cut_line > 0 ? " (the last one cut short)" : ""));
  }
  if (cut_line > 0 || reader.cut()) {
    log.truncated =
        path +
        (cut_line > 0 ? " truncated in line " + GroupedCount(cut_line)
                      : ": compressed data cut short after line " + GroupedCount(lines)) +
        ": recovered " + GroupedCount(log.scans.size()) +
        " scans of an unknown total; the rest is lost";
    log.notes.push_back(log.truncated);
  }
  return log;
}

}  // namespace slamrig::slam
