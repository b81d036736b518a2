#include "scenarios/benchmark_runner.h"

#include <signal.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "scenarios/benchmark_summary.h"
#include "scenarios/sweep_summary.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

// The estimator's figures results.csv carries, in its column order.
const std::vector<std::string>& FigureNames() {
  // `diverged`: the estimator's own verdict (1 or 0), `lost_s` the seconds it said it was lost;
  // both empty for one that does not judge itself.
  static const std::vector<std::string> names = {"ate_rmse_m", "ate_max_m",      "final_error_m",
                                                 "map_f1",     "loop_precision", "loop_recall",
                                                 "diverged",   "lost_s"};
  return names;
}

BenchmarkFigures ReadFigures(const std::string& metrics_path, const std::string& estimator) {
  BenchmarkFigures figures;
  const YAML::Node configs = YAML::LoadFile(metrics_path)["configs"];
  if (const YAML::Node mine = configs[estimator]) {
    for (const std::string& name : FigureNames()) {
      if (mine[name] && mine[name].IsScalar()) figures.estimator[name] = mine[name].as<double>();
    }
    if (mine["failure"]) figures.failure = mine["failure"].as<std::string>();
    if (mine["run"] && mine["run"]["wall_time_s"])
      figures.estimator["wall_time_s"] = mine["run"]["wall_time_s"].as<double>();
  }
  if (const YAML::Node baseline = configs[kBaselineName]; baseline && baseline["ate_rmse_m"])
    figures.baseline_ate_rmse_m = baseline["ate_rmse_m"].as<double>();
  return figures;
}

std::string Seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g s", s);
  return buffer;
}

// A finished run's row: its verdict from how it ended and, when it ended with figures, from them.
std::vector<std::string> BenchmarkRow(const BenchmarkSuite& suite, const BenchmarkRun& run,
                                      const std::string& dir, const RunEnd& end, bool* passed) {
  BenchmarkFigures figures;
  std::string status = "error", reason;
  const int code = WIFEXITED(end.status) ? WEXITSTATUS(end.status) : -1;
  const std::string metrics_path = (fs::path(dir) / "metrics.json").string();
  if (end.timed_out) {
    status = "timeout";
    reason = "still running after " + Seconds(suite.timeout_s);
  } else if (WIFSIGNALED(end.status)) {
    status = "crash";
    reason = std::string("killed by signal ") + std::to_string(WTERMSIG(end.status)) + " (" +
             ::strsignal(WTERMSIG(end.status)) + ")";
  } else if (code != 0 && code != 3) {
    reason = end.error_line.empty() ? "exit code " + std::to_string(code) : end.error_line;
  } else if (!fs::exists(metrics_path)) {
    reason = "no metrics.json";
  } else {
    try {
      figures = ReadFigures(metrics_path, suite.estimators[run.estimator].name);
      if (figures.failure.empty()) {
        status = JudgeBenchmarkRun(figures, suite.fail_above_m, &reason);
      } else {
        reason = figures.failure;  // an external program that failed: status stays "error"
      }
    } catch (const YAML::Exception& e) {
      reason = metrics_path + ": " + e.what();
    }
  }
  const BenchmarkDataset& d = suite.datasets[run.dataset];
  std::vector<std::string> row = {
      run.id, d.name, std::to_string(run.seed), suite.estimators[run.estimator].name,
      status, reason};
  for (const std::string& name : FigureNames()) {
    const auto v = figures.estimator.find(name);
    row.push_back(v == figures.estimator.end() ? "" : FormatCsvNumber(v->second));
  }
  row.push_back(figures.baseline_ate_rmse_m >= 0.0 ? FormatCsvNumber(figures.baseline_ate_rmse_m)
                                                   : "");
  const auto estimator_time = figures.estimator.find("wall_time_s");
  row.push_back(
      estimator_time == figures.estimator.end() ? "" : FormatCsvNumber(estimator_time->second));
  row.push_back(FormatCsvNumber(end.wall_s));
  row.push_back(FormatCsvNumber(end.peak_rss_mb));
  *passed = status == "pass";
  return row;
}

RunQueueSpec BenchmarkQueue(const BenchmarkSuite& suite, const RunQueueOptions& options) {
  const std::vector<BenchmarkRun> runs = ExpandBenchmark(suite);
  RunQueueSpec queue;
  for (std::size_t index = 0; index < runs.size(); ++index) {
    QueuedRun q;
    q.id = runs[index].id;
    q.dir = RunDir(options.out_dir, index);
    const std::string scenario = (fs::path(q.dir) / "scenario.yaml").string();
    q.args = {"run", scenario, "--out", q.dir, "--quiet"};
    queue.runs.push_back(std::move(q));
  }
  queue.header = BenchmarkHeader();
  queue.status_column = 4;
  queue.row = [suite, runs, dirs = queue.runs](std::size_t index, const RunEnd& end, bool* passed) {
    return BenchmarkRow(suite, runs[index], dirs[index].dir, end, passed);
  };
  queue.summarise = [suite, out_dir = options.out_dir] { WriteBenchmarkSummary(suite, out_dir); };
  return queue;
}

// Each run's scenario file, in its folder: what it runs, and how to run it again by hand. A
// folder resumed with another suite (a run's scenario differs) is refused before anything is
// written, never mixed.
void WriteScenarioFiles(const BenchmarkSuite& suite, const RunQueueSpec& queue) {
  const std::vector<BenchmarkRun> runs = ExpandBenchmark(suite);
  std::vector<std::string> texts;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    texts.push_back(BenchmarkScenarioYaml(suite, runs[i]));
    const fs::path path = fs::path(queue.runs[i].dir) / "scenario.yaml";
    if (!fs::exists(path)) continue;
    std::ifstream in(path, std::ios::binary);
    const std::string old((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (old != texts.back()) {
      throw ConfigError(path.string() +
                        ": written by another suite (this run's scenario "
                        "differs); use another --out");
    }
  }
  for (std::size_t i = 0; i < runs.size(); ++i) {
    fs::create_directories(queue.runs[i].dir);
    slam::WriteFileAtomically((fs::path(queue.runs[i].dir) / "scenario.yaml").string(), texts[i]);
  }
}

}  // namespace

const std::vector<std::string>& BenchmarkHeader() {
  static const std::vector<std::string> header = [] {
    std::vector<std::string> h = {"run", "dataset", "seed", "estimator", "status", "failure"};
    h.insert(h.end(), FigureNames().begin(), FigureNames().end());
    h.push_back("dead_reckoning_ate_rmse_m");
    h.insert(h.end(), BenchmarkTimingColumns().begin(), BenchmarkTimingColumns().end());
    return h;
  }();
  return header;
}

const std::vector<std::string>& BenchmarkTimingColumns() {
  static const std::vector<std::string> columns = {"estimator_time_s", "wall_time_s",
                                                   "peak_rss_mb"};
  return columns;
}

std::string JudgeBenchmarkRun(const BenchmarkFigures& figures, double fail_above_m,
                              std::string* reason) {
  const auto ate = figures.estimator.find("ate_rmse_m");
  if (ate == figures.estimator.end() || !std::isfinite(ate->second)) {
    *reason = "no ATE (no trajectory to score)";
    return "fail";
  }
  if (ate->second > fail_above_m) {
    char text[160];
    if (figures.baseline_ate_rmse_m >= 0.0) {
      std::snprintf(text, sizeof(text), "ATE %.3g m above %.3g m (dead reckoning's %.3g m)",
                    ate->second, fail_above_m, figures.baseline_ate_rmse_m);
    } else {
      std::snprintf(text, sizeof(text), "ATE %.3g m above %.3g m", ate->second, fail_above_m);
    }
    *reason = text;
    return "fail";
  }
  reason->clear();
  return "pass";
}

RunQueueSummary RunBenchmark(const BenchmarkSuite& suite, RunQueueOptions options) {
  options.command = "benchmark";
  options.spec_path = suite.path;
  options.timeout_s = suite.timeout_s;
  const RunQueueSpec queue = BenchmarkQueue(suite, options);
  slam::CheckOutputFolder(options.out_dir);
  WriteScenarioFiles(suite, queue);
  return RunQueue(queue, options);
}

bool RunBenchmarkRow(const BenchmarkSuite& suite, RunQueueOptions options, std::size_t row) {
  options.timeout_s = suite.timeout_s;
  const RunQueueSpec queue = BenchmarkQueue(suite, options);
  if (row >= queue.runs.size()) {
    throw ConfigError(suite.path + ": --row " + std::to_string(row) + " is past the suite's " +
                      std::to_string(queue.runs.size()) + " runs");
  }
  fs::create_directories(queue.runs[row].dir);
  slam::WriteFileAtomically((fs::path(queue.runs[row].dir) / "scenario.yaml").string(),
                            BenchmarkScenarioYaml(suite, ExpandBenchmark(suite)[row]));
  return RunQueueRow(queue, options, row);
}

}  // namespace slamrig::scenario
