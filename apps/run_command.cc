// `slamrig run [SCENARIO]`: simulation, SLAM and evaluation of one scenario, with a report.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "apps/live_flags.h"
#include "scenarios/scenario_runner.h"
#include "scenarios/scenario_spec.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"

namespace slamrig::app {

/// Exit code of a run whose expectations failed.
constexpr int kExitExpectationsFailed = 3;

int RunRunCommand(const std::vector<std::string>& command_line) {
  std::vector<std::string> args = command_line;
  LiveFlags live_flags;
  TakeLivePort(&args, &live_flags);
  std::string scenario_path = "office_loop";
  std::string out_dir;
  std::vector<std::string> overrides;
  std::uint64_t seed = 0;
  bool has_seed = false, view = false, quiet = false, record = false;
  std::string seed_text;
  ArgParser parser(
      "slamrig run", "[SCENARIO] [--out DIR] [options]",
      "Simulates the scenario's world and robot, runs each of its SLAM configurations\n"
      "on the same clock, scores them against the ground truth, writes a report folder\n"
      "(report.html, metrics.json, trajectories, maps, plots) and prints the table of\n"
      "expectations. Exit code 3 when an expectation fails.");
  parser.AddPositional("SCENARIO",
                       "scenario file, or a shipped scenario's name (office_loop, corridor, "
                       "intel_log, ...) [default: office_loop]",
                       &scenario_path,
                       /*required=*/false);
  parser.AddOption("out", "DIR", "report folder [default: out/<scenario name>]", &out_dir);
  parser.AddOption("seed", "N", "replace the scenario's seed", &seed_text);
  parser.AddRepeated(
      "set", "KEY=VALUE",
      "override a scenario key (slam.pf.particles=30), a world key (world.drive.laps=1) "
      "or a robot key (robot.lidar.range_noise_stddev_m=0.05)",
      &overrides);
  parser.AddFlag("view", "show the run live in a window (needs a display)", &view);
  parser.AddFlag("record",
                 "also write run.mcap in the report folder, the whole run for Foxglove "
                 "(docs/foxglove.md); `record: true` in the scenario does the same",
                 &record);
  AddLiveFlags(&parser, &live_flags);
  parser.AddFlag("quiet", "print only errors and the verdict line", &quiet);
  if (!parser.Parse(args)) return 0;
  if (!seed_text.empty()) {
    try {
      std::size_t used = 0;
      seed = std::stoull(seed_text, &used);
      has_seed = used == seed_text.size() && seed_text[0] != '-';
    } catch (const std::exception&) {
    }
    if (!has_seed)
      throw ConfigError("slamrig run: --seed: expected a non-negative integer, got '" + seed_text +
                        "'");
  }

  const scenario::ScenarioSpec spec =
      scenario::LoadScenario(scenario::FindScenarioFile(scenario_path), overrides,
                             has_seed ? std::optional<std::uint64_t>(seed) : std::nullopt);
  if (out_dir.empty()) out_dir = "out/" + spec.name;
  slam::CheckOutputFolder(out_dir);

  scenario::RunnerOptions options;
  options.view = view;
  if (record || spec.record) options.record_path = out_dir + "/run.mcap";
  const std::unique_ptr<scenario::LiveServer> live = StartLive("slamrig run", live_flags, &options);
  const bool tty = ::isatty(STDERR_FILENO) != 0;
  if (!quiet) {
    options.progress = [tty](double t, double duration) {
      if (tty) std::fprintf(stderr, "\r  simulated %.0f s (at most %.0f)", t, duration);
    };
    std::printf("%s: %s\n", spec.name.c_str(), spec.description.c_str());
  }
  const auto start = std::chrono::steady_clock::now();
  options.work_dir = out_dir;
  scenario::ScenarioResult result = scenario::RunScenario(spec, options);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!quiet && tty) std::fputc('\n', stderr);
  scenario::WriteReport(result, out_dir);
  FinishLive(live.get(), quiet);

  if (!quiet) {
    if (result.times_synthesised) {
      std::printf(
          "  %s in %.1f s (times synthesised from line order; no real-time factor), %d scans",
          spec.log->path.c_str(), wall_s, result.scans);
    } else {
      std::printf("  %.1f s simulated in %.1f s (%.0fx real time), %d scans", result.sim_time_s,
                  wall_s, result.sim_time_s / std::max(wall_s, 1e-9), result.scans);
    }
    if (result.scans_blacked_out) std::printf(" (%d blacked out)", result.scans_blacked_out);
    std::printf("\n");
    for (const auto& c : result.configs) {
      const auto get = [&](const char* m) {
        const auto it = c.metrics.find(m);
        return it == c.metrics.end() ? NAN : it->second;
      };
      std::printf("  %-16s ATE RMSE %.3f m, max %.3f m, final %.3f m, map F1 %.3f\n",
                  c.name.c_str(), get("ate_rmse_m"), get("ate_max_m"), get("final_error_m"),
                  get("map_f1"));
    }
    for (const auto& f : result.failures)
      std::printf("  %-16s FAILED (see below)\n", f.name.c_str());
    std::fputs(scenario::ExpectationTable(result).c_str(), stdout);
  }
  // Quiet or not, a failed configuration is named: it is why the verdict is FAIL.
  if (quiet) {
    for (const auto& f : result.failures)
      std::printf("  %s (%s) failed: %s\n", f.name.c_str(), f.algorithm.c_str(), f.message.c_str());
  }
  std::printf("%s: %s -> %s/report.html\n", spec.name.c_str(), result.passed ? "PASS" : "FAIL",
              out_dir.c_str());
  return result.passed ? 0 : kExitExpectationsFailed;
}

}  // namespace slamrig::app
