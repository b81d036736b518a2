#include "scenarios/sweep_runner.h"

#include <fcntl.h>
#include <signal.h>
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

#include "scenarios/child_process.h"
#include "scenarios/scenario_spec.h"
#include "scenarios/slurm_sweep.h"
#include "scenarios/sweep_summary.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

using Clock = std::chrono::steady_clock;

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

std::vector<std::string> MetricsOf(const SweepSpec& spec) {
  return spec.metrics.empty() ? DefaultMetrics(spec) : spec.metrics;
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
  return SpawnChild(args, dir + "/log.txt", index);
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

// What an earlier, interrupted sweep left in results.csv.
struct ResumeState {
  bool has_header = false;       ///< the file exists with a header line
  std::set<std::string> done;    ///< run ids with a row
  std::set<std::string> failed;  ///< of them, those whose status is not pass
};

// Reads results.csv for a resumed sweep, which must have been started with the same grid and
// metrics (another header is a ConfigError). A sweep killed mid-write leaves at most a partial
// last line: the file is cut back to its complete lines.
ResumeState ReadResumeState(const SweepSpec& spec, const std::vector<std::string>& metrics,
                            const std::string& csv_path) {
  namespace fs = std::filesystem;
  ResumeState state;
  if (!fs::exists(csv_path)) return state;
  std::ifstream in(csv_path, std::ios::binary);
  std::string contents((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t keep = contents.rfind('\n') == std::string::npos ? 0 : contents.rfind('\n') + 1;
  if (keep != contents.size()) fs::resize_file(csv_path, keep);
  std::istringstream lines(contents.substr(0, keep));
  std::string line;
  if (!std::getline(lines, line)) return state;
  if (SplitCsv(line) != ResultsHeader(spec, metrics)) {
    throw ConfigError(csv_path +
                      ": written by another sweep (its columns differ); use another --out");
  }
  state.has_header = true;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const std::vector<std::string> fields = SplitCsv(line);
    state.done.insert(fields[0]);
    const std::size_t status = spec.parameters.size() + 2;
    if (fields.size() <= status || fields[status] != "pass") state.failed.insert(fields[0]);
  }
  return state;
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

  const std::vector<std::string> metrics = MetricsOf(spec);
  const ResumeState resume = ReadResumeState(spec, metrics, csv_path);
  const std::set<std::string>& done = resume.done;
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (done.count(runs[i].id)) {
      ++summary.already_done;
      summary.failed += static_cast<int>(resume.failed.count(runs[i].id));
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
  if (!resume.has_header) AppendLine(fd, JoinCsv(ResultsHeader(spec, metrics)), csv_path);

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

}  // namespace slamrig::scenario
