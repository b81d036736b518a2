// slamrig: the one command line of the test bench. Each subcommand lives in its own
// *_command.cc; this file dispatches and turns every error into one line and an exit code.

#include <unistd.h>

#include <climits>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"
#ifdef SLAMRIG_HAS_PYTHON
#include "python/embed.h"
#endif

namespace slamrig::app {

std::string SelfPath() {
  char buffer[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buffer, sizeof(buffer) - 1);
  if (n <= 0) throw std::runtime_error("cannot find the slamrig binary (/proc/self/exe)");
  return std::string(buffer, static_cast<std::size_t>(n));
}

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      {"map", "build the occupancy map of a log from its logged poses", RunMapCommand},
      {"simulate", "simulate a robot in a world: CARMEN log plus ground truth", RunSimulateCommand},
      {"slam", "dead reckoning or particle-filter SLAM on a log, scored against its reference",
       RunSlamCommand},
      {"eval", "score a trajectory against a reference: ATE, RPE, relations metric",
       RunEvalCommand},
      {"run", "run a scenario: simulation, SLAM, evaluation, report and verdict", RunRunCommand},
      {"sweep", "run a scenario over a grid of parameters and seeds, all cores", RunSweepCommand},
      {"benchmark", "every estimator of a suite on every dataset: leaderboard and failures",
       RunBenchmarkCommand},
      {"world", "generate a procedural world (office, warehouse, corridor, campus, maze)",
       RunWorldCommand},
      {"optimize", "optimise a 2D pose graph (g2o file) with Ceres: chi2, iterations, time",
       RunOptimizeCommand},
      {"odometry-noise", "a log's own odometry error per scan against its reference",
       RunOdometryNoiseCommand},
  };
  return commands;
}

namespace {

constexpr int kExitUsage = 2;
constexpr int kExitDataError = 1;
/// An output could not be written (EX_IOERR of sysexits.h): a sweep runs such a run again.
constexpr int kExitOutputError = 74;

// Exit code of a command stopped by `signal`: the shell's convention, 128 + signal.
int ReportInterrupted(int signal) {
  // On a terminal the line may follow a progress line that ends in '\r' and the echoed ^C.
  if (::isatty(STDERR_FILENO) != 0) std::fputc('\n', stderr);
  std::fprintf(stderr, "slamrig: interrupted by %s; no partial output was left in place\n",
               SignalName(signal).c_str());
  return 128 + signal;
}

void PrintHelp() {
  std::string help =
      "slamrig: a test bench for 2D SLAM\n\n"
      "Usage: slamrig <command> [arguments]\n\n"
      "Commands:\n";
  for (const Command& c : Commands()) {
    const std::string name = c.name;
    help +=
        "  " + name + std::string(name.size() < 12 ? 12 - name.size() : 1, ' ') + c.summary + "\n";
  }
  help +=
      "\nRun 'slamrig <command> --help' for a command's arguments.\n"
      "Datasets are found through SLAMRIG_DATA_DIR (default ../shared/datasets).\n";
  std::fputs(help.c_str(), stdout);
}

int Main(int argc, char** argv) {
  InstallInterruptHandlers();
#ifdef SLAMRIG_HAS_PYTHON
  python::EnableEmbeddedPython();
#endif
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    PrintHelp();
    return kExitUsage;
  }
  const std::string& name = args[0];
  if (name == "-h" || name == "--help" || (name == "help" && args.size() == 1)) {
    PrintHelp();
    return 0;
  }
  // `slamrig help map` is `slamrig map --help`.
  const bool help_for_command = name == "help";
  const std::string& command = help_for_command ? args[1] : name;
  const std::vector<std::string> command_args =
      help_for_command ? std::vector<std::string>{"--help"}
                       : std::vector<std::string>(args.begin() + 1, args.end());
  if (name == "--version") {
    std::puts("slamrig 0.1.0");
    return 0;
  }
  for (const Command& c : Commands()) {
    if (command != c.name) continue;
    try {
      const int code = c.run(command_args);
      // A signal after the last check came when the outputs were complete (every command that
      // stops early on a signal throws): the exit code says what the folder holds, a finished
      // command, as a caller that checks the code and the folder together (a sweep, a script)
      // must find them.
      if (const int signal = InterruptSignal(); signal != 0) {
        std::fprintf(stderr, "slamrig: %s came after the outputs were complete; they are kept\n",
                     SignalName(signal).c_str());
      }
      return code;
    } catch (const std::exception& e) {
      // Whatever failed after a signal failed because of it (a wait cut short, a child gone).
      if (InterruptSignal() != 0) return ReportInterrupted(InterruptSignal());
      std::fprintf(stderr, "slamrig: error: %s\n", e.what());
      if (dynamic_cast<const ConfigError*>(&e) != nullptr) return kExitUsage;
      if (dynamic_cast<const OutputError*>(&e) != nullptr ||
          dynamic_cast<const std::filesystem::filesystem_error*>(&e) != nullptr) {
        return kExitOutputError;
      }
      return kExitDataError;
    }
  }
  std::fprintf(stderr, "slamrig: error: unknown command '%s' (see 'slamrig --help')\n",
               command.c_str());
  return kExitUsage;
}

}  // namespace
}  // namespace slamrig::app

int main(int argc, char** argv) { return slamrig::app::Main(argc, argv); }
