#include "scenarios/sweep_runner.h"

#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "scenarios/scenario_spec.h"
#include "scenarios/sweep_summary.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

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

// The results.csv row of a finished run; `*passed` when its expectations held.
std::vector<std::string> ResultRow(const SweepSpec& spec, const std::vector<std::string>& metrics,
                                   const SweepRun& run, const std::string& run_dir,
                                   const RunEnd& end, bool* passed) {
  const std::string metrics_path = (std::filesystem::path(run_dir) / "metrics.json").string();
  std::string state = "error";
  std::map<std::string, double> values;
  const int code = WIFEXITED(end.status) ? WEXITSTATUS(end.status) : -1;
  if (!end.timed_out && (code == 0 || code == 3) && std::filesystem::exists(metrics_path)) {
    try {
      values = ReadRunMetrics(metrics_path, &state);
    } catch (const std::exception&) {
      state = "error";
    }
  }
  std::vector<std::string> row = {run.id};
  for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
    row.push_back(spec.parameters[p].values[run.value_index[p]]);
  }
  row.push_back(std::to_string(run.seed));
  row.push_back(state);
  for (const auto& m : metrics) {
    const auto v = values.find(m);
    row.push_back(v == values.end() ? "" : FormatCsvNumber(v->second));
  }
  row.push_back(FormatCsvNumber(end.wall_s));
  *passed = state == "pass";
  return row;
}

// The sweep as a queue of `slamrig run SCENARIO --out runs/<n> --seed S --set key=value ...
// --quiet` children.
RunQueueSpec SweepQueue(const SweepSpec& spec, const RunQueueOptions& options) {
  const std::vector<SweepRun> runs = ExpandSweep(spec);
  const std::vector<std::string> metrics = MetricsOf(spec);
  RunQueueSpec queue;
  for (std::size_t index = 0; index < runs.size(); ++index) {
    const SweepRun& run = runs[index];
    QueuedRun q;
    q.id = run.id;
    q.dir = RunDir(options.out_dir, index);
    q.args = {"run",    spec.scenario_path,       "--out",  q.dir,
              "--seed", std::to_string(run.seed), "--quiet"};
    for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
      q.args.push_back("--set");
      q.args.push_back(spec.parameters[p].key + "=" +
                       spec.parameters[p].values[run.value_index[p]]);
    }
    queue.runs.push_back(std::move(q));
  }
  queue.header = ResultsHeader(spec, metrics);
  queue.status_column = spec.parameters.size() + 2;
  queue.row = [spec, metrics, runs, dirs = queue.runs](std::size_t index, const RunEnd& end,
                                                       bool* passed) {
    return ResultRow(spec, metrics, runs[index], dirs[index].dir, end, passed);
  };
  queue.summarise = [spec, out_dir = options.out_dir] { WriteSweepSummary(spec, out_dir); };
  return queue;
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

RunQueueSummary RunSweep(const SweepSpec& spec, const RunQueueOptions& options) {
  return RunQueue(SweepQueue(spec, options), options);
}

bool RunSweepRow(const SweepSpec& spec, const RunQueueOptions& options, std::size_t row) {
  const RunQueueSpec queue = SweepQueue(spec, options);
  if (row >= queue.runs.size()) {
    throw ConfigError(spec.path + ": --row " + std::to_string(row) + " is past the grid's " +
                      std::to_string(queue.runs.size()) + " rows");
  }
  return RunQueueRow(queue, options, row);
}

}  // namespace slamrig::scenario
