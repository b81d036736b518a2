#include "scenarios/sweep_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "scenarios/plot.h"
#include "scenarios/scenario_spec.h"
#include "scenarios/slurm_sweep.h"
#include "slam/fusion/consistency.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

using Clock = std::chrono::steady_clock;

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string JoinCsv(const std::vector<std::string>& fields) {
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + CsvField(fields[i]);
  return line;
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

std::string FormatValue(double v) {
  if (!std::isfinite(v)) return "";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", v);
  return buffer;
}

// Every "config.metric" number in a run's metrics.json (YAML reads JSON).
std::map<std::string, double> ReadRunMetrics(const std::string& path, std::string* passed) {
  std::map<std::string, double> metrics;
  const YAML::Node root = YAML::LoadFile(path);
  if (root["passed"]) *passed = root["passed"].as<bool>() ? "pass" : "fail";
  for (const auto& config : root["configs"]) {
    for (const auto& metric : config.second) {
      if (!metric.second.IsScalar()) continue;
      try {
        metrics[config.first.as<std::string>() + "." + metric.first.as<std::string>()] =
            metric.second.as<double>();
      } catch (const YAML::Exception&) {
        // Not a number (a name or a flag): not a metric.
      }
    }
  }
  return metrics;
}

std::string Duration(double seconds) {
  const int s = static_cast<int>(std::lround(seconds));
  char buffer[32];
  if (s >= 3600) {
    std::snprintf(buffer, sizeof(buffer), "%d:%02d:%02d", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%d:%02d", s / 60, s % 60);
  }
  return buffer;
}

// Appends one line with a single write() and makes it durable before the next run starts.
void AppendLine(int fd, const std::string& line, const std::string& path) {
  const std::string text = line + "\n";
  if (::write(fd, text.data(), text.size()) != static_cast<ssize_t>(text.size()) ||
      ::fsync(fd) != 0) {
    throw OutputError(path + ": cannot append: " + std::strerror(errno));
  }
}

// Every known metric of every SLAM configuration of the scenario, except the wall-clock one,
// which differs between identical runs. Read from the scenario as the first run sees it.
std::vector<std::string> DefaultMetrics(const SweepSpec& spec) {
  std::vector<std::string> overrides;
  for (const auto& p : spec.parameters) overrides.push_back(p.key + "=" + p.values.front());
  const ScenarioSpec scenario = LoadScenario(spec.scenario_path, overrides);
  std::vector<std::string> metrics;
  for (const slam::EstimatorConfig& config : scenario.configs) {
    for (const std::string& m : MetricsOf(config)) {
      if (m != "realtime_factor") metrics.push_back(config.name + "." + m);
    }
  }
  return metrics;
}

// A running `slamrig run`. Its stdout goes to runs/<n>/log.txt; its stderr comes through a
// pipe, so that its error line reaches the sweep even when log.txt cannot be written (a full
// disk), and is appended to log.txt when it ends.
struct Child {
  std::size_t run = 0;
  Clock::time_point start;
  pid_t pid = -1;
  int stderr_fd = -1;  ///< read end of the child's stderr, non-blocking
  std::string log_path;
  std::string stderr_text;  ///< what it wrote there (the last 64 KiB)
};

// Exit code of `slamrig run` when it could not write its output (apps/main.cc).
constexpr int kExitOutputError = 74;

// How a child `slamrig run` ended, as far as results.csv is concerned.
enum class ChildEnd {
  kResult,       ///< it ran to a verdict or failed by itself: its row is recorded
  kStopped,      ///< a signal stopped it: no row, the next sweep runs it again
  kOutputError,  ///< it could not write its folder: no row, and the sweep stops
};

ChildEnd ClassifyEnd(int status) {
  if (WIFSIGNALED(status)) {
    const int s = WTERMSIG(status);
    // A crash is the run's own failure; these come from outside (a user, scancel, the OOM killer).
    return s == SIGTERM || s == SIGINT || s == SIGKILL || s == SIGHUP ? ChildEnd::kStopped
                                                                      : ChildEnd::kResult;
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 0;
  if (code == 128 + SIGINT || code == 128 + SIGTERM) return ChildEnd::kStopped;
  if (code == kExitOutputError) return ChildEnd::kOutputError;
  return ChildEnd::kResult;
}

// The last non-empty line a child wrote to stderr (its error line, without slamrig's prefix),
// or `fallback`.
std::string LastErrorLine(const Child& child, const std::string& fallback) {
  std::istringstream in(child.stderr_text);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  const std::string prefix = "slamrig: error: ";
  if (last.rfind(prefix, 0) == 0) last = last.substr(prefix.size());
  return last.empty() ? fallback : last;
}

// Reads what is there on the child's stderr pipe; closes it at end of file.
void DrainStderr(Child* child) {
  char buffer[4096];
  while (child->stderr_fd >= 0) {
    const ssize_t n = ::read(child->stderr_fd, buffer, sizeof(buffer));
    if (n > 0) {
      child->stderr_text.append(buffer, static_cast<std::size_t>(n));
      constexpr std::size_t kKeep = 64 * 1024;
      if (child->stderr_text.size() > kKeep)
        child->stderr_text.erase(0, child->stderr_text.size() - kKeep);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    ::close(child->stderr_fd);  // end of file, or an error: nothing more will come
    child->stderr_fd = -1;
  }
}

// A child that ended: the rest of its stderr, appended to its log.txt (best effort: the disk
// may be full; the text stays in `child` for the sweep's error line).
void FinishChild(Child* child) {
  // Only the child held the pipe's write end (O_CLOEXEC elsewhere), so end of file is near; a
  // deadline all the same, should a process it started keep the pipe open.
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(2);
  while (child->stderr_fd >= 0 && Clock::now() < deadline) {
    DrainStderr(child);
    if (child->stderr_fd >= 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (child->stderr_fd >= 0) {
    ::close(child->stderr_fd);
    child->stderr_fd = -1;
  }
  if (child->stderr_text.empty()) return;
  std::ofstream log(child->log_path, std::ios::app | std::ios::binary);
  log << child->stderr_text;
}

// The child processes of a sweep. However the sweep ends (done, interrupted, an error thrown),
// the ones still running are sent SIGTERM, so that they remove their temporary files, and are
// waited for: nothing of a stopped sweep goes on writing behind its back.
class Children {
 public:
  Children() = default;
  Children(const Children&) = delete;
  Children& operator=(const Children&) = delete;
  ~Children() { StopAll(); }

  void Add(const Child& child) { running_[child.pid] = child; }
  std::size_t size() const { return running_.size(); }
  bool empty() const { return running_.empty(); }

  /// Waits until a child ends and returns it with its wait status; nullopt when none is left
  /// or SIGINT/SIGTERM arrived (polled every 20 ms: a signal between a check and a blocking
  /// waitpid would otherwise wait for the next child to end).
  std::optional<std::pair<Child, int>> WaitAny() {
    while (!running_.empty() && InterruptSignal() == 0) {
      for (auto& [pid, child] : running_) DrainStderr(&child);
      int status = 0;
      const pid_t pid = ::waitpid(-1, &status, WNOHANG);
      if (pid < 0 && errno != EINTR) return std::nullopt;
      if (pid <= 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        continue;
      }
      const auto it = running_.find(pid);
      if (it == running_.end()) continue;
      Child child = std::move(it->second);
      running_.erase(it);
      FinishChild(&child);
      return std::make_pair(std::move(child), status);
    }
    return std::nullopt;
  }

  /// SIGTERM to every running child, then waits for them (SIGKILL after 10 s).
  void StopAll() {
    for (const auto& [pid, child] : running_) ::kill(pid, SIGTERM);
    const Clock::time_point deadline = Clock::now() + std::chrono::seconds(10);
    while (!running_.empty()) {
      for (auto& [pid, child] : running_) DrainStderr(&child);
      int status = 0;
      const pid_t pid = ::waitpid(-1, &status, WNOHANG);
      if (pid > 0) {
        if (const auto it = running_.find(pid); it != running_.end()) {
          FinishChild(&it->second);
          running_.erase(it);
        }
      } else if (pid < 0 && errno == ECHILD) {
        break;
      } else if (Clock::now() > deadline) {
        for (const auto& [p, child] : running_) ::kill(p, SIGKILL);
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
    for (auto& [pid, child] : running_) {
      if (child.stderr_fd >= 0) ::close(child.stderr_fd);
    }
    running_.clear();
  }

 private:
  std::map<pid_t, Child> running_;
};

std::vector<std::string> MetricsOf(const SweepSpec& spec) {
  return spec.metrics.empty() ? DefaultMetrics(spec) : spec.metrics;
}

std::string RunDir(const std::string& out_dir, std::size_t index) {
  char name[16];
  std::snprintf(name, sizeof(name), "%04zu", index);
  return (std::filesystem::path(out_dir) / "runs" / name).string();
}

// Starts `slamrig run SCENARIO --out runs/<n> --seed S --set key=value ... --quiet` for grid
// row `index`, its output in runs/<n>/log.txt (stderr through a pipe, see Child).
Child SpawnRun(const SweepSpec& spec, const SweepRunnerOptions& options, const SweepRun& run,
               std::size_t index) {
  namespace fs = std::filesystem;
  const std::string dir = RunDir(options.out_dir, index);
  fs::create_directories(dir);
  fs::remove(fs::path(dir) / "metrics.json");
  std::vector<std::string> args = {
      options.slamrig_binary,   "run",    spec.scenario_path, "--out", dir, "--seed",
      std::to_string(run.seed), "--quiet"};
  for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
    args.push_back("--set");
    args.push_back(spec.parameters[p].key + "=" + spec.parameters[p].values[run.value_index[p]]);
  }
  Child child;
  child.run = index;
  child.start = Clock::now();
  child.log_path = dir + "/log.txt";
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("pipe failed: ") + std::strerror(errno));
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    // A child never outlives a killed sweep: it would finish a run nobody records. SIGTERM
    // (not SIGKILL), so that it still removes its temporary files.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(128 + SIGTERM);  // the sweep died before prctl
    const int log = ::open(child.log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (log >= 0) ::dup2(log, STDOUT_FILENO);
    ::dup2(pipe_fds[1], STDERR_FILENO);  // dup2 clears O_CLOEXEC on the copy
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    std::perror("execv");
    ::_exit(127);
  }
  ::close(pipe_fds[1]);
  ::fcntl(pipe_fds[0], F_SETFL, O_NONBLOCK);
  child.pid = pid;
  child.stderr_fd = pipe_fds[0];
  return child;
}

// The results.csv row of a finished run (wait status `status`, `wall_s` seconds); `*state` is
// pass, fail or error.
std::vector<std::string> ResultRow(const SweepSpec& spec, const std::vector<std::string>& metrics,
                                   const SweepRun& run, const std::string& run_dir, int status,
                                   double wall_s, std::string* state) {
  const std::string metrics_path = (std::filesystem::path(run_dir) / "metrics.json").string();
  *state = "error";
  std::map<std::string, double> values;
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if ((code == 0 || code == 3) && std::filesystem::exists(metrics_path)) {
    try {
      values = ReadRunMetrics(metrics_path, state);
    } catch (const std::exception&) {
      *state = "error";
    }
  }
  std::vector<std::string> row = {run.id};
  for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
    row.push_back(spec.parameters[p].values[run.value_index[p]]);
  }
  row.push_back(std::to_string(run.seed));
  row.push_back(*state);
  for (const auto& m : metrics) {
    const auto v = values.find(m);
    row.push_back(v == values.end() ? "" : FormatValue(v->second));
  }
  row.push_back(FormatValue(wall_s));
  return row;
}

}  // namespace

std::vector<std::string> ResultsHeader(const SweepSpec& spec,
                                       const std::vector<std::string>& metrics) {
  std::vector<std::string> header = {"run"};
  for (const auto& p : spec.parameters) header.push_back(p.key);
  header.push_back("seed");
  header.push_back("status");
  for (const auto& m : metrics) header.push_back(m);
  header.push_back("wall_time_s");
  return header;
}

void CheckSweepGrid(const SweepSpec& spec) {
  // LoadScenario names an overridden value's error by its --set argument; the sweep's user wrote
  // no --set, so that prefix gives way to the value's place in the sweep file.
  auto rule_of = [](const ConfigError& e) {
    const std::string what = e.what();
    const std::size_t colon = what.find(": ");
    return what.rfind("--set ", 0) == 0 && colon != std::string::npos ? what.substr(colon + 2)
                                                                      : what;
  };
  // Each value alone, over the base scenario: a failure is that value's.
  for (const SweepParameter& p : spec.parameters) {
    for (std::size_t v = 0; v < p.values.size(); ++v) {
      try {
        LoadScenario(spec.scenario_path, {p.key + "=" + p.values[v]});
      } catch (const ConfigError& e) {
        const std::string where =
            v < p.where.size() ? p.where[v] : spec.path + ": parameters." + p.key;
        throw ConfigError(where + ": " + rule_of(e));
      }
    }
  }
  // Then every combination, when there are few enough to check quickly.
  std::size_t combinations = 1;
  for (const SweepParameter& p : spec.parameters) {
    combinations = combinations > kMaxCheckedCombinations / p.values.size()
                       ? kMaxCheckedCombinations + 1
                       : combinations * p.values.size();
  }
  if (spec.parameters.size() < 2 || combinations > kMaxCheckedCombinations) return;
  std::vector<std::size_t> index(spec.parameters.size(), 0);
  do {
    std::vector<std::string> overrides;
    std::string named;
    for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
      const SweepParameter& parameter = spec.parameters[p];
      overrides.push_back(parameter.key + "=" + parameter.values[index[p]]);
      named += (p ? " " : "") + overrides.back();
    }
    try {
      LoadScenario(spec.scenario_path, overrides);
    } catch (const ConfigError& e) {
      throw ConfigError(spec.path + ": parameters: the combination " + named + ": " + rule_of(e));
    }
  } while (NextGridPoint(spec, &index));
}

SweepSummary RunSweep(const SweepSpec& spec, const SweepRunnerOptions& options) {
  namespace fs = std::filesystem;
  const std::vector<SweepRun> runs = ExpandSweep(spec);
  SweepSummary summary;
  summary.total = static_cast<int>(runs.size());
  slam::CheckOutputFolder(options.out_dir);
  fs::create_directories(fs::path(options.out_dir) / "runs");
  const std::string csv_path = (fs::path(options.out_dir) / "results.csv").string();

  // A resumed sweep must have been started with the same grid and metrics.
  std::vector<std::string> metrics = MetricsOf(spec);
  std::set<std::string> done;
  std::vector<std::string> header;
  if (fs::exists(csv_path)) {
    // Keep complete lines only: a sweep killed mid-write leaves at most a partial last line.
    std::ifstream in(csv_path, std::ios::binary);
    std::string contents((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t keep =
        contents.rfind('\n') == std::string::npos ? 0 : contents.rfind('\n') + 1;
    if (keep != contents.size()) fs::resize_file(csv_path, keep);
    std::istringstream lines(contents.substr(0, keep));
    std::string line;
    if (std::getline(lines, line)) {
      header = SplitCsv(line);
      if (header != ResultsHeader(spec, metrics)) {
        throw ConfigError(csv_path +
                          ": written by another sweep (its columns differ); use another --out");
      }
      while (std::getline(lines, line)) {
        if (!line.empty()) done.insert(SplitCsv(line)[0]);
      }
    }
  }
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (done.count(runs[i].id)) {
      ++summary.already_done;
    } else {
      todo.push_back(i);
    }
  }
  const int fd = ::open(csv_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw OutputError(csv_path + ": cannot open: " + std::strerror(errno));
  const std::unique_ptr<int, void (*)(int*)> close_fd(new int(fd), [](int* f) {
    ::close(*f);
    delete f;
  });
  if (header.empty()) AppendLine(fd, JoinCsv(ResultsHeader(spec, metrics)), csv_path);

  const int jobs = options.jobs > 0
                       ? options.jobs
                       : std::max(1, static_cast<int>(::sysconf(_SC_NPROCESSORS_ONLN)));
  Children running;
  std::size_t next = 0;
  int finished_now = 0;
  const Clock::time_point sweep_start = Clock::now();
  const bool tty = ::isatty(STDERR_FILENO) != 0;
  auto report = [&] {
    if (!options.progress) return;
    const int finished = summary.already_done + finished_now;
    const double elapsed = std::chrono::duration<double>(Clock::now() - sweep_start).count();
    const int remaining = summary.total - finished;
    std::string eta = "--:--";
    if (finished_now > 0) eta = Duration(elapsed / finished_now * remaining);
    constexpr int kWidth = 30;
    const int filled = summary.total > 0 ? kWidth * finished / summary.total : kWidth;
    const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '-');
    std::fprintf(stderr, "%s[%s] %d/%d runs, %zu running, %d failed, elapsed %s, ETA %s%s",
                 tty ? "\r" : "", bar.c_str(), finished, summary.total, running.size(),
                 summary.failed, Duration(elapsed).c_str(), eta.c_str(), tty ? "  " : "\n");
    std::fflush(stderr);
  };

  auto start_run = [&](std::size_t index) {
    running.Add(SpawnRun(spec, options, runs[index], index));
  };

  if (options.backend == SweepBackend::kSlurm) {
    // One job array for every missing row; rows are merged in grid order once it is over.
    const std::vector<std::string> lines = RunRowsOnSlurm(options, todo);
    for (std::size_t k = 0; k < todo.size(); ++k) {
      const std::vector<std::string> fields = SplitCsv(lines[k]);
      if (lines[k].empty() || fields.size() < spec.parameters.size() + 3 ||
          fields[spec.parameters.size() + 2] != "pass") {
        ++summary.failed;
      }
      if (lines[k].empty()) {  // the task left no row: the next sweep runs it again
        std::fprintf(stderr, "slurm: row %zu left no result (see %s); the next sweep runs it\n",
                     todo[k], SlurmTaskLogPath(options.out_dir, todo[k]).c_str());
        continue;
      }
      AppendLine(fd, lines[k], csv_path);
      ++summary.ran;
    }
    WriteSweepSummary(spec, options.out_dir);
    return summary;
  }

  report();
  while (next < todo.size() || !running.empty()) {
    while (next < todo.size() && static_cast<int>(running.size()) < jobs && InterruptSignal() == 0)
      start_run(todo[next++]);
    const auto ended = running.WaitAny();
    // SIGINT/SIGTERM: `running` stops the children on the way out, and their rows stay missing.
    ThrowIfInterrupted();
    if (!ended) break;
    const auto& [child, status] = *ended;
    const std::string run_dir = RunDir(options.out_dir, child.run);
    switch (ClassifyEnd(status)) {
      case ChildEnd::kStopped:
        ++summary.failed;
        std::fprintf(stderr, "%s: stopped by a signal; the next sweep runs it again\n",
                     run_dir.c_str());
        continue;
      case ChildEnd::kOutputError:
        // The disk is full or the folder read-only: every other run would fail the same way.
        throw OutputError(LastErrorLine(child, run_dir + ": the run could not write its output"));
      case ChildEnd::kResult:
        break;
    }
    const double wall = std::chrono::duration<double>(Clock::now() - child.start).count();
    std::string state;
    const std::vector<std::string> row =
        ResultRow(spec, metrics, runs[child.run], run_dir, status, wall, &state);
    if (state != "pass") ++summary.failed;
    AppendLine(fd, JoinCsv(row), csv_path);
    ++finished_now;
    ++summary.ran;
    report();
  }
  if (options.progress && tty) std::fputc('\n', stderr);
  WriteSweepSummary(spec, options.out_dir);
  return summary;
}

bool RunSweepRow(const SweepSpec& spec, const SweepRunnerOptions& options, std::size_t row) {
  const std::vector<SweepRun> runs = ExpandSweep(spec);
  if (row >= runs.size()) {
    throw ConfigError(spec.path + ": --row " + std::to_string(row) + " is past the grid's " +
                      std::to_string(runs.size()) + " rows");
  }
  const std::vector<std::string> metrics = MetricsOf(spec);
  const Clock::time_point start = Clock::now();
  Children running;
  running.Add(SpawnRun(spec, options, runs[row], row));
  const auto ended = running.WaitAny();
  // scancel: SIGTERM to the task and its child; no row file, so a resumed sweep runs it again.
  ThrowIfInterrupted();
  if (!ended) throw std::runtime_error("waitpid: " + std::string(std::strerror(errno)));
  const auto& [child, status] = *ended;
  const std::string run_dir = RunDir(options.out_dir, row);
  switch (ClassifyEnd(status)) {
    case ChildEnd::kStopped:
      throw std::runtime_error(run_dir + ": stopped by a signal; its row is not written");
    case ChildEnd::kOutputError:
      throw OutputError(LastErrorLine(child, run_dir + ": the run could not write its output"));
    case ChildEnd::kResult:
      break;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  std::string state;
  const std::vector<std::string> fields =
      ResultRow(spec, metrics, runs[row], run_dir, status, wall, &state);
  const std::string path = SweepRowPath(options.out_dir, row);
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  slam::WriteFileAtomically(path,
                            JoinCsv(ResultsHeader(spec, metrics)) + "\n" + JoinCsv(fields) + "\n");
  return state == "pass";
}

std::string SweepRowPath(const std::string& out_dir, std::size_t row) {
  char name[32];
  std::snprintf(name, sizeof(name), "%04zu.csv", row);
  return (std::filesystem::path(out_dir) / "rows" / name).string();
}

int WriteSweepSummary(const SweepSpec& spec, const std::string& out_dir) {
  namespace fs = std::filesystem;
  std::ifstream in(fs::path(out_dir) / "results.csv");
  std::string line;
  if (!std::getline(in, line)) return 0;
  const std::vector<std::string> header = SplitCsv(line);
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    if (!line.empty()) rows.push_back(SplitCsv(line));
  }
  const std::size_t num_params = spec.parameters.size();
  const std::size_t first_metric = num_params + 3;
  auto number = [](const std::string& s) {
    if (s.empty()) return std::nan("");
    try {
      std::size_t used = 0;
      const double v = std::stod(s, &used);
      return used == s.size() ? v : std::nan("");
    } catch (const std::exception&) {
      return std::nan("");
    }
  };

  std::string html =
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>sweep summary</title>"
      "<style>body{font-family:sans-serif;margin:2em}img{max-width:100%;border:1px solid #ddd}"
      "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px "
      "8px}</style></head><body>"
      "<h1>Sweep summary</h1><p>Scenario: " +
      spec.scenario_path + "; " + std::to_string(rows.size()) +
      " runs in results.csv; each point is the mean over seeds, bars the min-max spread.</p>";
  int plots = 0;
  for (std::size_t m = first_metric; m + 1 < header.size(); ++m) {
    for (std::size_t p = 0; p < num_params; ++p) {
      const SweepParameter& param = spec.parameters[p];
      // x positions: the values themselves when numeric, else their index.
      std::vector<double> xs;
      bool numeric = true;
      for (const auto& v : param.values) {
        xs.push_back(number(v));
        numeric = numeric && std::isfinite(xs.back());
      }
      if (!numeric) {
        for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = static_cast<double>(i);
      }
      // One series per combination of the other parameters.
      std::map<std::string, std::map<std::size_t, std::vector<double>>> series;
      for (const auto& row : rows) {
        if (row.size() != header.size()) continue;
        std::string others;
        for (std::size_t q = 0; q < num_params; ++q) {
          if (q != p)
            others += (others.empty() ? "" : ", ") + spec.parameters[q].key + "=" + row[1 + q];
        }
        const auto value = std::find(param.values.begin(), param.values.end(), row[1 + p]);
        if (value == param.values.end()) continue;
        const double v = number(row[m]);
        if (std::isfinite(v)) {
          series[others][static_cast<std::size_t>(value - param.values.begin())].push_back(v);
        }
      }
      if (series.empty()) continue;
      std::vector<PlotSeries> plot;
      for (const auto& [label, by_value] : series) {
        PlotSeries s;
        s.label = label;
        s.colour = PaletteColour(plot.size());
        s.markers = true;
        for (const auto& [index, samples] : by_value) {
          double sum = 0, lo = samples.front(), hi = samples.front();
          for (const double v : samples) sum += v, lo = std::min(lo, v), hi = std::max(hi, v);
          s.x.push_back(xs[index]);
          s.y.push_back(sum / static_cast<double>(samples.size()));
          s.y_low.push_back(lo);
          s.y_high.push_back(hi);
        }
        plot.push_back(std::move(s));
      }
      PlotOptions options;
      options.title = header[m] + " vs " + param.key;
      options.x_label = param.key + (numeric ? "" : " (index of value)");
      options.y_label = header[m];
      const std::string file = "summary_" + header[m] + "__" + param.key + ".png";
      slam::WriteFileAtomically((fs::path(out_dir) / file).string(),
                                RenderLinePlotPng(plot, options));
      html += "<h2>" + options.title + "</h2><img src=\"" + file + "\">";
      ++plots;
    }
  }
  // Consistency: the final pose's NEES is independent across seeds, so its mean over a grid
  // point's seeds is an ANEES with a chi-square acceptance region (Bar-Shalom et al. 2001,
  // Sec. 5.4.2). A time-averaged NEES (mean_nees) is not: its samples are correlated in time.
  // A landmark estimator's landmark_anees is a run's mean NEES over its mapped landmarks (2 dof
  // each); weighted by the run's pillars_mapped (a metric of the same configuration, which the
  // sweep must list) it pools into the ANEES over every landmark of every run. The region then
  // treats the landmarks as independent, which they are not quite (they share the pose's error).
  const auto ends_with = [](const std::string& name, const std::string& suffix) {
    return name.size() >= suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  for (std::size_t m = first_metric; m + 1 < header.size(); ++m) {
    const std::string& name = header[m];
    int dimension = 0;
    std::size_t weight_column = 0;  // 0: one sample per run
    std::string what;
    if (ends_with(name, "final_nees")) {
      dimension = 3;
      what = "pose, 3 dof";
    } else if (ends_with(name, "landmark_anees")) {
      const std::string mapped =
          name.substr(0, name.size() - std::string("landmark_anees").size()) + "pillars_mapped";
      const auto it = std::find(header.begin() + first_metric, header.end(), mapped);
      if (it == header.end()) continue;
      weight_column = static_cast<std::size_t>(it - header.begin());
      dimension = 2;
      what = "landmarks, 2 dof, pooled over the mapped landmarks of all runs";
    } else {
      continue;
    }
    // One group per grid point (the swept values), in results.csv order: (value, weight) pairs.
    std::vector<std::string> labels;
    std::map<std::string, std::vector<std::pair<double, double>>> samples;
    for (const auto& row : rows) {
      if (row.size() != header.size()) continue;
      std::string label;
      for (std::size_t q = 0; q < num_params; ++q)
        label += (label.empty() ? "" : ", ") + spec.parameters[q].key + "=" + row[1 + q];
      if (label.empty()) label = "all runs";
      const double v = number(row[m]);
      const double w = weight_column > 0 ? number(row[weight_column]) : 1.0;
      if (!std::isfinite(v) || !std::isfinite(w) || !(w > 0.0)) continue;
      if (!samples.count(label)) labels.push_back(label);
      samples[label].emplace_back(v, w);
    }
    if (labels.empty()) continue;
    html +=
        "<h2>ANEES of " + name + " (" + what +
        ") with the two-sided 95 % chi-square region</h2><table><tr><th>grid "
        "point</th><th>runs</th><th>ANEES</th><th>lower</th><th>upper</th><th>verdict</th></tr>";
    PlotSeries anees, lower, upper;
    anees.label = "ANEES";
    anees.colour = PaletteColour(0);
    anees.markers = true;
    lower.label = "95 % lower";
    upper.label = "95 % upper";
    lower.colour = upper.colour = PaletteColour(1);
    lower.dashed = upper.dashed = true;
    for (std::size_t g = 0; g < labels.size(); ++g) {
      const std::vector<std::pair<double, double>>& v = samples[labels[g]];
      double sum = 0.0, weight = 0.0;
      for (const auto& [x, w] : v) {
        sum += w * x;
        weight += w;
      }
      const double mean = sum / weight;
      const slam::NeesBounds bounds =
          slam::AneesBounds(dimension, static_cast<int>(std::lround(weight)));
      const bool inside = mean >= bounds.lower && mean <= bounds.upper;
      char cells[256];
      std::snprintf(cells, sizeof(cells), "<td>%zu</td><td>%.3f</td><td>%.3f</td><td>%.3f</td>",
                    v.size(), mean, bounds.lower, bounds.upper);
      html += "<tr><td>" + labels[g] + "</td>" + cells + "<td>" +
              (inside ? "inside"
                      : (mean < bounds.lower ? "below (pessimistic)" : "above (optimistic)")) +
              "</td></tr>";
      // The bounds span [g - 0.4, g + 0.4] round each point, so that one point draws them too.
      anees.x.push_back(static_cast<double>(g));
      anees.y.push_back(mean);
      for (const double x : {static_cast<double>(g) - 0.4, static_cast<double>(g) + 0.4}) {
        lower.x.push_back(x);
        upper.x.push_back(x);
        lower.y.push_back(bounds.lower);
        upper.y.push_back(bounds.upper);
      }
    }
    html += "</table>";
    PlotOptions options;
    options.title = "ANEES of " + name + " per grid point";
    options.x_label = "grid point (table order)";
    options.y_label = "ANEES";
    const std::string file = "summary_anees_" + name + ".png";
    slam::WriteFileAtomically((fs::path(out_dir) / file).string(),
                              RenderLinePlotPng({anees, lower, upper}, options));
    html += "<img src=\"" + file + "\">";
    ++plots;
  }
  html += "</body></html>\n";
  slam::WriteFileAtomically((fs::path(out_dir) / "summary.html").string(), html);
  return plots;
}

}  // namespace slamrig::scenario
