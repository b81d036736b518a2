// `slamrig sweep SWEEP.yaml --out DIR`: a scenario over a parameter grid and seeds.

#include <cstdio>
#include <filesystem>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "scenarios/sweep_runner.h"
#include "slam/types/error.h"

namespace slamrig::app {
int RunSweepCommand(const std::vector<std::string>& args) {
  std::string sweep_path;
  scenario::RunQueueOptions options;
  bool quiet = false;
  ArgParser parser("slamrig sweep", "SWEEP.yaml --out DIR [options]",
                   "Runs the sweep's scenario for every combination of its parameter values and\n"
                   "every seed, several runs at a time. Each finished run is appended to\n"
                   "DIR/results.csv at once; run the same command again after an interruption\n"
                   "and it runs only what is missing. At the end, DIR/summary.html shows each\n"
                   "metric against each parameter with the spread over seeds.");
  parser.AddPositional("SWEEP.yaml", "the sweep file (see scenarios/sweeps/)", &sweep_path);
  parser.AddOption("out", "DIR", "output folder (created; reused to resume)", &options.out_dir);
  parser.AddOption("jobs", "N", "runs at a time (0: one per core)", &options.jobs);
  parser.AddFlag("quiet", "no progress bar", &quiet);
  std::string backend = "local";
  int row = -1;
  parser.AddOption("backend", "local|slurm",
                   "where runs execute: child processes here, or one Slurm job array (sbatch)",
                   &backend);
  parser.AddOption("row", "K", "run grid row K alone into DIR/rows/ (what a Slurm task does)",
                   &row);
  if (!parser.Parse(args)) return 0;
  if (backend != "local" && backend != "slurm") {
    throw ConfigError("slamrig sweep: --backend = " + backend + "; must be local or slurm");
  }
  options.backend =
      backend == "slurm" ? scenario::RunBackend::kSlurm : scenario::RunBackend::kLocal;
  options.spec_path = sweep_path;
  if (options.out_dir.empty()) throw ConfigError("slamrig sweep: --out DIR is required");
  if (options.jobs < 0)
    throw ConfigError("slamrig sweep: --jobs = " + std::to_string(options.jobs) + "; must be >= 0");
  options.progress = !quiet;
  options.slamrig_binary = SelfPath();

  const scenario::SweepSpec spec = scenario::LoadSweepSpec(sweep_path);
  if (row >= 0) {
    return scenario::RunSweepRow(spec, options, static_cast<std::size_t>(row)) ? 0 : 3;
  }
  // Every value of the grid resolves before a run starts or a file is written (a Slurm array is
  // checked before it is submitted; its tasks, --row, were checked then).
  scenario::CheckSweepGrid(spec);
  const scenario::RunQueueSummary s = scenario::RunSweep(spec, options);
  std::printf("%s: %d runs (%d from an earlier sweep, %d now), %d failed -> %s/results.csv\n",
              sweep_path.c_str(), s.total, s.already_done, s.ran, s.failed,
              options.out_dir.c_str());
  return s.failed > 0 ? 3 : 0;
}

}  // namespace slamrig::app
