#include "scenarios/sweep_spec.h"

#include <filesystem>
#include <set>
#include <system_error>

#include "slam/config/yaml_node.h"

namespace slamrig::scenario {

SweepSpec LoadSweepSpec(const std::string& path) {
  const YamlNode root = YamlNode::LoadFile(path);
  SweepSpec spec;
  spec.path = path;
  const YamlNode scenario = root.Required("scenario");
  std::filesystem::path scenario_path = scenario.As<std::string>();
  if (scenario_path.is_relative())
    scenario_path = std::filesystem::path(path).parent_path() / scenario_path;
  std::error_code error;  // e.g. a name too long for the OS: does not exist either
  if (!std::filesystem::exists(scenario_path, error)) {
    scenario.Fail("scenario file '" + scenario_path.string() + "' does not exist");
  }
  spec.scenario_path = scenario_path.lexically_normal().string();

  const YamlNode seeds = root.Required("seeds");
  if (seeds.IsSequence()) {
    std::set<std::uint64_t> seen;
    for (const YamlNode& s : seeds.Elements()) {
      const auto seed = s.As<std::uint64_t>();
      if (!seen.insert(seed).second) s.Fail("seed " + std::to_string(seed) + " listed twice");
      spec.seeds.push_back(seed);
    }
  } else {
    const int count = seeds.As<int>();
    if (count < 1 || count > 100000)
      seeds.Fail("must be a count in [1, 100000] or a list of seeds");
    for (int i = 1; i <= count; ++i) spec.seeds.push_back(static_cast<std::uint64_t>(i));
  }
  if (spec.seeds.empty()) seeds.Fail("no seeds");

  const YamlNode parameters = root.Required("parameters");
  for (const std::string& key : parameters.Keys()) {
    const YamlNode values = parameters.Required(key);
    SweepParameter p;
    p.key = key;
    for (const YamlNode& v : values.Elements()) {
      if (!v.IsScalar()) v.Fail("sweep values must be scalars");
      p.values.push_back(v.As<std::string>());
      p.where.push_back(v.Where());
    }
    if (p.values.empty()) values.Fail("needs at least one value");
    spec.parameters.push_back(std::move(p));
  }
  // ExpandSweep holds every run in memory: a grid past kMaxSweepRuns is a typo, not a plan.
  std::size_t total = spec.seeds.size();
  for (const SweepParameter& p : spec.parameters) {
    total = total > kMaxSweepRuns / p.values.size() ? kMaxSweepRuns + 1 : total * p.values.size();
  }
  if (total > kMaxSweepRuns) {
    parameters.Fail("seeds x parameter values is more than " + std::to_string(kMaxSweepRuns) +
                    " runs");
  }
  if (auto metrics = root.Optional("metrics")) {
    for (const YamlNode& m : metrics->Elements()) {
      const std::string name = m.As<std::string>();
      if (name.find('.') == std::string::npos) m.Fail("expected config.metric, e.g. pf.ate_rmse_m");
      spec.metrics.push_back(name);
    }
  }
  root.CheckAllKeysUsed();
  return spec;
}

std::vector<SweepRun> ExpandSweep(const SweepSpec& spec) {
  std::vector<SweepRun> runs;
  std::vector<std::size_t> index(spec.parameters.size(), 0);
  do {
    for (const std::uint64_t seed : spec.seeds) {
      SweepRun run;
      run.value_index = index;
      run.seed = seed;
      for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
        run.id += spec.parameters[p].key + "=" + spec.parameters[p].values[index[p]] + " ";
      }
      run.id += "seed=" + std::to_string(seed);
      runs.push_back(std::move(run));
    }
  } while (NextGridPoint(spec, &index));
  return runs;
}

bool NextGridPoint(const SweepSpec& spec, std::vector<std::size_t>* index) {
  // Odometer increment, last parameter fastest.
  for (std::size_t p = spec.parameters.size(); p > 0;) {
    --p;
    if (++(*index)[p] < spec.parameters[p].values.size()) return true;
    (*index)[p] = 0;
  }
  return false;
}

}  // namespace slamrig::scenario
