// `slamrig benchmark SUITE.yaml --out DIR`: every estimator of a suite on every dataset.

#include <cstdio>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "scenarios/benchmark_runner.h"
#include "slam/types/error.h"

namespace slamrig::app {

int RunBenchmarkCommand(const std::vector<std::string>& args) {
  std::string suite_path;
  scenario::RunQueueOptions options;
  bool quiet = false;
  std::string backend = "local";
  int row = -1;
  ArgParser parser(
      "slamrig benchmark", "SUITE.yaml --out DIR [options]",
      "Runs every estimator of the suite on every dataset (real logs, perturbed logs,\n"
      "generated worlds at each seed), several runs at a time, each killed at the suite's\n"
      "timeout. Each finished run is appended to DIR/results.csv at once (run the same\n"
      "command again after an interruption and it runs only what is missing); at the end\n"
      "DIR/summary.html shows the leaderboard, each dataset's ATE distribution and the worst\n"
      "cases. A run fails when it crashes, times out or errors, or when its ATE is above\n"
      "the suite's fail_above_m (1 m unless it says). Exit 3 when any run failed.");
  parser.AddPositional("SUITE.yaml", "the suite file (see suites/)", &suite_path);
  parser.AddOption("out", "DIR", "output folder (created; reused to resume)", &options.out_dir);
  parser.AddOption("jobs", "N", "runs at a time (0: one per core)", &options.jobs);
  parser.AddFlag("quiet", "no progress bar", &quiet);
  parser.AddOption("backend", "local|slurm",
                   "where runs execute: child processes here, or one Slurm job array (sbatch)",
                   &backend);
  parser.AddOption("row", "K", "run row K alone into DIR/rows/ (what a Slurm task does)", &row);
  if (!parser.Parse(args)) return 0;
  if (backend != "local" && backend != "slurm") {
    throw ConfigError("slamrig benchmark: --backend = " + backend + "; must be local or slurm");
  }
  options.backend =
      backend == "slurm" ? scenario::RunBackend::kSlurm : scenario::RunBackend::kLocal;
  if (options.out_dir.empty()) throw ConfigError("slamrig benchmark: --out DIR is required");
  if (options.jobs < 0) {
    throw ConfigError("slamrig benchmark: --jobs = " + std::to_string(options.jobs) +
                      "; must be >= 0");
  }
  options.progress = !quiet;
  options.slamrig_binary = SelfPath();

  const scenario::BenchmarkSuite suite = scenario::LoadBenchmarkSuite(suite_path);
  if (row >= 0) {
    return scenario::RunBenchmarkRow(suite, options, static_cast<std::size_t>(row)) ? 0 : 3;
  }
  const scenario::RunQueueSummary s = scenario::RunBenchmark(suite, options);
  std::printf("%s: %d runs (%d from an earlier benchmark, %d now), %d failed -> %s/summary.html\n",
              suite_path.c_str(), s.total, s.already_done, s.ran, s.failed,
              options.out_dir.c_str());
  return s.failed > 0 ? 3 : 0;
}

}  // namespace slamrig::app
