#include "scenarios/benchmark_spec.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <system_error>

#include "scenarios/scenario_spec.h"
#include "sim/worldgen/worldgen.h"
#include "slam/config/yaml_node.h"
#include "slam/io/log_perturbation.h"
#include "slam/io/log_reader.h"
#include "slam/pipeline/estimator_config.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

// The most runs a suite may expand to: more is a typo in a seed range, not a plan.
constexpr std::size_t kMaxBenchmarkRuns = 100'000;

std::vector<std::uint64_t> ReadSeeds(const YamlNode& node) {
  std::vector<std::uint64_t> seeds;
  std::set<std::uint64_t> seen;
  if (node.IsSequence()) {
    for (const YamlNode& s : node.Elements()) {
      const auto seed = s.As<std::uint64_t>();
      if (!seen.insert(seed).second) s.Fail("seed " + std::to_string(seed) + " listed twice");
      seeds.push_back(seed);
    }
  } else if (node.IsMap()) {
    const auto from = node.Get<std::uint64_t>("from");
    const auto to = node.Get<std::uint64_t>("to");
    if (to < from)
      node.Fail("to (" + std::to_string(to) + ") is below from (" + std::to_string(from) + ")");
    if (to - from >= kMaxBenchmarkRuns)
      node.Fail("more than " + std::to_string(kMaxBenchmarkRuns) + " seeds");
    for (std::uint64_t s = from; s <= to; ++s) seeds.push_back(s);
  } else {
    const int count = node.As<int>();
    if (count < 1 || count > static_cast<int>(kMaxBenchmarkRuns))
      node.Fail("must be a count in [1, " + std::to_string(kMaxBenchmarkRuns) +
                "], a list of seeds or {from: A, to: B}");
    for (int i = 1; i <= count; ++i) seeds.push_back(static_cast<std::uint64_t>(i));
  }
  if (seeds.empty()) node.Fail("no seeds");
  return seeds;
}

// A log named relative to the suite file, or else to SLAMRIG_DATA_DIR; absolute either way.
std::string ResolveLog(const YamlNode& node) {
  const std::string text = node.As<std::string>();
  const std::string beside = node.ResolvePath(text);
  std::error_code error;
  const std::string resolved = fs::exists(beside, error) ? beside : slam::ResolveLogPath(text);
  if (!fs::exists(resolved, error) && !fs::exists(fs::path(resolved).parent_path(), error)) {
    node.Fail("no log '" + text + "' beside the suite or in the data folder (" + slam::DataDir() +
              ")");
  }
  return fs::absolute(resolved).lexically_normal().string();
}

BenchmarkDataset ReadDataset(const YamlNode& node) {
  BenchmarkDataset d;
  d.where = node.Where();
  d.name = node.Get<std::string>("name");
  if (d.name.empty() || d.name.find_first_of(",\"\n ") != std::string::npos)
    node.Required("name").Fail("must be a non-empty name without spaces, commas or quotes");
  const auto log = node.Optional("log");
  const auto generate = node.Optional("generate");
  const auto world = node.Optional("world");
  if (log.has_value() + generate.has_value() + world.has_value() != 1)
    node.Fail(
        "needs exactly one of log: (a recorded log), generate: (generated worlds) and world: (a "
        "world file)");
  if (log) {
    d.log = ResolveLog(*log);
    if (const auto perturb = node.Optional("perturb")) {
      slam::ParseLogPerturbation(*perturb);
      d.perturb_yaml = perturb->ToFlowYaml();
    }
    if (const auto max_scans = node.Optional("max_scans")) {
      const int n = max_scans->As<int>();
      if (n < 1) max_scans->Fail("must be >= 1");
      d.max_scans = static_cast<std::size_t>(n);
    }
  } else {
    if (generate) {
      if (generate->Has("seed"))
        generate->Required("seed").Fail(
            "the worlds' seeds are the dataset's seeds: list them there");
      const sim::worldgen::GenerateSpec spec = sim::worldgen::ParseGenerateSpec(*generate);
      generate->ThrowIfInvalid(spec.Validate());
      d.generate_yaml = generate->ToFlowYaml();
    } else {
      d.world = world->ResolvePath(world->As<std::string>());
      std::error_code error;
      if (!fs::is_regular_file(d.world, error)) world->Fail("no world file '" + d.world + "'");
      if (const auto overrides = node.Optional("world_overrides")) {
        for (const std::string& key : overrides->Keys()) {
          if (!overrides->Required(key).IsScalar())
            overrides->Required(key).Fail("a dotted key and a scalar value");
        }
        d.world_overrides_yaml = overrides->ToFlowYaml();
      }
    }
    if (const auto robot = node.Optional("robot")) {
      const std::string text = robot->As<std::string>();
      const bool is_file =
          text.find('/') != std::string::npos || fs::path(text).extension() == ".yaml";
      d.robot = is_file ? robot->ResolvePath(text) : text;
      std::error_code error;
      if (is_file && !fs::exists(d.robot, error)) robot->Fail("no robot file '" + d.robot + "'");
    }
    if (const auto overrides = node.Optional("robot_overrides")) {
      for (const std::string& key : overrides->Keys()) {
        if (!overrides->Required(key).IsScalar())
          overrides->Required(key).Fail("a dotted key and a scalar value");
      }
      d.robot_overrides_yaml = overrides->ToFlowYaml();
    }
  }
  if (const auto duration = node.Optional("duration_s")) {
    d.duration_s = duration->As<double>();
    if (!(d.duration_s > 0.0 && d.duration_s <= 1e6)) duration->Fail("must be in (0, 1e6] s");
  }
  d.seeds = node.Has("seeds") ? ReadSeeds(node.Required("seeds")) : std::vector<std::uint64_t>{1};
  return d;
}

// Resolves each dataset's scenario at its first seed with every estimator, as its runs will;
// an error names the dataset's place in the suite.
void CheckSuite(const BenchmarkSuite& suite) {
  const fs::path scratch =
      fs::temp_directory_path() / ("slamrig-suite-check-" + std::to_string(::getpid()) + ".yaml");
  struct Remove {
    fs::path path;
    ~Remove() {
      std::error_code ignored;
      fs::remove(path, ignored);
    }
  } remove{scratch};
  for (std::size_t d = 0; d < suite.datasets.size(); ++d) {
    BenchmarkRun run;
    run.dataset = d;
    run.seed = suite.datasets[d].seeds.front();
    for (std::size_t e = 0; e < suite.estimators.size(); ++e) {
      run.estimator = e;
      {
        std::ofstream out(scratch);
        out << BenchmarkScenarioYaml(suite, run);
      }
      try {
        LoadScenario(scratch.string());
      } catch (const ConfigError& error) {
        std::string what = error.what();
        // The scratch file's name means nothing to the suite's author.
        if (what.rfind(scratch.string(), 0) == 0) what = what.substr(what.find(' ') + 1);
        throw ConfigError(suite.datasets[d].where + " (" + suite.datasets[d].name + ", estimator " +
                          suite.estimators[e].name + "): " + what);
      }
    }
  }
}

}  // namespace

BenchmarkSuite LoadBenchmarkSuite(const std::string& path) {
  const YamlNode root = YamlNode::LoadFile(path);
  BenchmarkSuite suite;
  suite.path = path;
  if (const auto timeout = root.Optional("timeout_s")) {
    suite.timeout_s = timeout->As<double>();
    if (!(suite.timeout_s > 0.0)) timeout->Fail("must be > 0 seconds");
  }
  if (const auto bound = root.Optional("fail_above_m")) {
    suite.fail_above_m = bound->As<double>();
    if (!(suite.fail_above_m > 0.0) || !std::isfinite(suite.fail_above_m)) {
      bound->Fail("must be a finite number of metres > 0");
    }
  }
  const YamlNode estimators = root.Required("estimators");
  for (const std::string& name : estimators.Keys()) {
    const YamlNode node = estimators.Required(name);
    const slam::EstimatorConfig config = slam::ParseEstimatorConfig(name, node);
    if (name == kBaselineName && config.algorithm != "dead-reckoning")
      node.Fail(std::string("the name ") + kBaselineName +
                " is the baseline every run carries; its algorithm must be dead-reckoning");
    // A run's scenario lives in its own folder: an external program's ./ and ../ arguments,
    // relative to the suite, go into it as resolved here.
    std::string yaml = node.ToFlowYaml();
    if (config.algorithm == "external") {
      YAML::Emitter written;
      slam::WriteEstimatorConfig(config, &written);
      YAML::Node resolved = YAML::Load(yaml);
      resolved["command"] = YAML::Load(written.c_str())["command"];
      YAML::Emitter flow;
      flow << YAML::Flow << resolved;
      yaml = flow.c_str();
    }
    suite.estimators.push_back({name, yaml});
  }
  if (suite.estimators.empty()) estimators.Fail("needs at least one estimator");
  const YamlNode datasets = root.Required("datasets");
  std::set<std::string> names;
  std::size_t total = 0;
  for (const YamlNode& node : datasets.Elements()) {
    BenchmarkDataset d = ReadDataset(node);
    if (!names.insert(d.name).second)
      node.Required("name").Fail("dataset '" + d.name + "' is named twice");
    total += d.seeds.size() * suite.estimators.size();
    if (total > kMaxBenchmarkRuns)
      node.Fail("the suite has more than " + std::to_string(kMaxBenchmarkRuns) + " runs");
    suite.datasets.push_back(std::move(d));
  }
  if (suite.datasets.empty()) datasets.Fail("needs at least one dataset");
  root.CheckAllKeysUsed();
  CheckSuite(suite);
  return suite;
}

std::vector<BenchmarkRun> ExpandBenchmark(const BenchmarkSuite& suite) {
  std::vector<BenchmarkRun> runs;
  for (std::size_t d = 0; d < suite.datasets.size(); ++d) {
    for (const std::uint64_t seed : suite.datasets[d].seeds) {
      for (std::size_t e = 0; e < suite.estimators.size(); ++e) {
        BenchmarkRun run;
        run.dataset = d;
        run.estimator = e;
        run.seed = seed;
        run.id = suite.datasets[d].name + " seed=" + std::to_string(seed) + " " +
                 suite.estimators[e].name;
        runs.push_back(std::move(run));
      }
    }
  }
  return runs;
}

std::string BenchmarkScenarioYaml(const BenchmarkSuite& suite, const BenchmarkRun& run) {
  const BenchmarkDataset& d = suite.datasets[run.dataset];
  const BenchmarkEstimator& e = suite.estimators[run.estimator];
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << d.name + "_" + e.name;
  out << YAML::Key << "description" << YAML::Value
      << "Benchmark run (" + fs::path(suite.path).filename().string() + "): " + e.name + " on " +
             d.name + ", seed " + std::to_string(run.seed) + ".";
  if (!d.log.empty()) {
    out << YAML::Key << "source" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "log" << YAML::Value << d.log;
    if (!d.perturb_yaml.empty())
      out << YAML::Key << "perturb" << YAML::Value << YAML::Load(d.perturb_yaml);
    if (d.max_scans > 0) out << YAML::Key << "max_scans" << YAML::Value << d.max_scans;
    out << YAML::EndMap;
  } else {
    if (!d.world.empty()) {
      out << YAML::Key << "world" << YAML::Value << d.world;
      if (!d.world_overrides_yaml.empty())
        out << YAML::Key << "world_overrides" << YAML::Value << YAML::Load(d.world_overrides_yaml);
    } else {
      YAML::Node generate = YAML::Load(d.generate_yaml);
      generate["seed"] = run.seed;
      out << YAML::Key << "world" << YAML::Value << YAML::BeginMap << YAML::Key << "generate"
          << YAML::Value << YAML::Flow << generate << YAML::EndMap;
    }
    if (!d.robot.empty()) out << YAML::Key << "robot" << YAML::Value << d.robot;
    if (!d.robot_overrides_yaml.empty())
      out << YAML::Key << "robot_overrides" << YAML::Value << YAML::Load(d.robot_overrides_yaml);
  }
  out << YAML::Key << "seed" << YAML::Value << run.seed;
  if (d.duration_s > 0.0) out << YAML::Key << "duration_s" << YAML::Value << d.duration_s;
  out << YAML::Key << "slam" << YAML::Value << YAML::BeginMap;
  if (e.name != kBaselineName) {
    out << YAML::Key << kBaselineName << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "algorithm" << YAML::Value << "dead-reckoning" << YAML::EndMap;
  }
  out << YAML::Key << e.name << YAML::Value << YAML::Flow << YAML::Load(e.yaml);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace slamrig::scenario
