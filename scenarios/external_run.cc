#include "scenarios/external_run.h"

#include <signal.h>
#include <string.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "scenarios/child_process.h"
#include "slam/io/bag/bag_sink.h"
#include "slam/io/carmen_sink.h"
#include "slam/io/ece276a_writer.h"
#include "slam/io/map_server.h"
#include "slam/io/tum_io.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The input files of `estimator`'s records in its format below `dir`; returns the path the
// program is given as {input}. The records go without the truth: the program must not see it.
std::string WriteInput(const slam::ExternalEstimator& estimator, const ExternalSource& source,
                       const fs::path& dir) {
  slam::WheelOdometryOptions odometry;
  odometry.robot = estimator.context().robot;
  odometry.use_gyro = estimator.context().use_gyro;
  std::unique_ptr<slam::RecordSink> sink;
  fs::path input;
  switch (estimator.options().input) {
    case slam::ExternalInput::kCarmen: {
      input = dir / "input.log";
      slam::CarmenSinkOptions carmen;
      carmen.odometry = odometry;
      carmen.params = source.carmen_params;
      sink = std::make_unique<slam::CarmenSink>(input.string(), carmen);
      break;
    }
    case slam::ExternalInput::kMcap:
    case slam::ExternalInput::kSqlite3: {
      input = dir / "input";
      slam::BagSinkOptions bag;
      bag.writer.storage = estimator.options().input == slam::ExternalInput::kMcap
                               ? slam::BagStorage::kMcap
                               : slam::BagStorage::kSqlite3;
      bag.writer.ticks_per_revolution = source.ticks_per_revolution;
      bag.odometry = odometry;
      try {
        sink = std::make_unique<slam::BagSink>(input.string(), bag);
      } catch (const std::runtime_error& e) {
        throw OutputError(e.what());
      }
      break;
    }
    case slam::ExternalInput::kEce276a:
      input = dir / "input";
      fs::create_directories(input);
      sink = std::make_unique<slam::Ece276aSink>(input.string());
      break;
  }
  for (const Record& record : estimator.records()) {
    ThrowIfInterrupted();
    sink->Add(record, nullptr);
  }
  sink->Commit();
  return input.string();
}

// The program's output read back: the trajectory matched to the scans, and the map beside it.
void ReadOutput(const fs::path& output, const slam::ExternalEstimator& estimator,
                ExternalOutcome* outcome) {
  if (!fs::is_regular_file(output)) {
    outcome->failure = "exited with code 0 but wrote no " + output.string();
    return;
  }
  Trajectory poses;
  try {
    poses = slam::ReadTum(output.string(), /*in_time_order=*/false);
  } catch (const ParseError& e) {
    outcome->failure = std::string("its output is not a TUM trajectory: ") + e.what();
    return;
  }
  std::vector<Time> scan_times;
  for (const Record& r : estimator.records()) {
    if (const auto* scan = std::get_if<LaserScan>(&r)) scan_times.push_back(scan->time);
  }
  std::string error;
  std::optional<Trajectory> matched = MatchPosesToScans(poses, scan_times, &error);
  if (!matched) {
    outcome->failure = output.string() + ": " + error;
    return;
  }
  outcome->poses = std::move(*matched);
  fs::path map = output;
  map.replace_extension(".yaml");
  if (!fs::exists(map)) return;
  try {
    outcome->map = slam::GridFromMapImage(slam::ReadMapServerMap(map.string()));
  } catch (const ParseError& e) {
    outcome->failure = std::string("its map is not a map_server map: ") + e.what();
  } catch (const ConfigError& e) {
    outcome->failure = std::string("its map is not a map_server map: ") + e.what();
  }
}

}  // namespace

long ProcessResidentKb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  }
  return 0;
}

std::string LastLines(const std::string& path, std::size_t count) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    lines.push_back(line);
    if (lines.size() > count) lines.erase(lines.begin());
  }
  std::string text;
  for (const std::string& l : lines) text += (text.empty() ? "" : " | ") + l;
  constexpr std::size_t kMaxChars = 600;
  if (text.size() > kMaxChars) text = "..." + text.substr(text.size() - kMaxChars);
  return text;
}

std::string ExternalEndFailure(bool timed_out, int status, double timeout_s) {
  if (timed_out) {
    std::ostringstream s;
    s << "still running after timeout_s = " << timeout_s << " s; killed";
    return s.str();
  }
  if (WIFSIGNALED(status)) {
    return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
           ::strsignal(WTERMSIG(status)) + ")";
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return code == 0 ? "" : "exit code " + std::to_string(code);
}

std::optional<Trajectory> MatchPosesToScans(const Trajectory& poses,
                                            const std::vector<Time>& scan_times,
                                            std::string* error) {
  if (poses.size() != scan_times.size()) {
    *error = "wrote " + std::to_string(poses.size()) + " poses for " +
             std::to_string(scan_times.size()) + " scans (one pose per scan, at its stamp)";
    return std::nullopt;
  }
  // Half the smallest gap between distinct scan stamps, so that a pose can match one scan only;
  // equal stamps (a log's) are told apart by order.
  double tolerance_s = kExternalStampToleranceS;
  for (std::size_t i = 1; i < scan_times.size(); ++i) {
    const double gap = std::abs(SecondsBetween(scan_times[i], scan_times[i - 1]));
    if (gap > 0.0) tolerance_s = std::min(tolerance_s, 0.5 * gap);
  }
  Trajectory matched;
  for (std::size_t i = 0; i < scan_times.size(); ++i) {
    const StampedPose& p = poses.poses()[i];
    const double off_s = std::abs(SecondsBetween(p.time, scan_times[i]));
    if (!(off_s <= tolerance_s)) {
      char text[1024];
      std::snprintf(text, sizeof(text),
                    "pose %zu is stamped %.9f s, scan %zu at %.9f s (%.3g s apart; tolerance "
                    "%.3g s): poses must be one per scan, in scan order, at the scans' stamps",
                    i + 1, p.time.seconds(), i + 1, scan_times[i].seconds(), off_s, tolerance_s);
      *error = text;
      return std::nullopt;
    }
    matched.Append(scan_times[i], p.pose);
  }
  return matched;
}

ExternalOutcome RunExternal(const std::string& name, const slam::ExternalEstimator& estimator,
                            const ExternalSource& source, const std::string& work_dir) {
  ExternalOutcome outcome;
  const fs::path dir = fs::absolute(fs::path(work_dir) / "external" / name);
  std::error_code ec;
  fs::remove_all(dir, ec);  // an earlier run's input and output must not be read as this one's
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir.string() + ": cannot create: " + ec.message());
  const auto write_start = Clock::now();
  const std::string input = WriteInput(estimator, source, dir);
  outcome.input_write_s = std::chrono::duration<double>(Clock::now() - write_start).count();

  const fs::path output = dir / "output.tum";
  const slam::ExternalEstimatorOptions& options = estimator.options();
  const std::vector<std::string> args = slam::SubstituteExternalArguments(
      options.command, input, output.string(), estimator.context().seed);
  SpawnOptions spawn;
  spawn.stdout_path = (fs::path(work_dir) / (name + "_stdout.txt")).string();
  spawn.stderr_path = (fs::path(work_dir) / (name + "_stderr.txt")).string();
  spawn.working_dir = dir.string();
  spawn.search_path = true;
  spawn.null_stdin = true;
  Children children;
  const long parent_kb = ProcessResidentKb();
  Child child = SpawnChild(args, spawn, 0);
  child.deadline = child.start + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(options.timeout_s));
  children.Add(child);
  const std::optional<std::pair<Child, int>> end = children.WaitAny();
  if (!end) {
    ThrowIfInterrupted();  // SIGINT/SIGTERM: `children` stops the program on the way out
    throw std::runtime_error("waiting for " + args.front() + " failed");
  }
  const auto& [ended, status] = *end;
  outcome.child_wall_s = std::chrono::duration<double>(Clock::now() - ended.start).count();
  // ru_maxrss is the program's own peak only when above the fork's copy of this process (at
  // most this process's resident size); else the peak polled while it ran (a lower bound, short
  // of a peak in its last 20 ms).
  outcome.peak_rss_kb = ended.peak_rss_kb > parent_kb ? ended.peak_rss_kb : ended.polled_peak_kb;
  outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  outcome.failure = ExternalEndFailure(ended.timed_out, status, options.timeout_s);
  if (outcome.failure.empty()) ReadOutput(output, estimator, &outcome);
  if (!outcome.failure.empty()) {
    const std::string tail = LastLines(spawn.stderr_path, 3);
    outcome.failure =
        args.front() + ": " + outcome.failure + (tail.empty() ? "" : "; stderr: " + tail);
    outcome.poses = Trajectory();
    outcome.map.reset();
  }
  return outcome;
}

}  // namespace slamrig::scenario
