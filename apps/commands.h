#pragma once

#include <string>
#include <vector>

namespace slamrig::app {

/// One `slamrig` subcommand: it parses its own arguments (without the program and command
/// names), returns the process exit code, and throws ConfigError/ParseError for bad input.
struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>& args);
};

int RunMapCommand(const std::vector<std::string>& args);
int RunSimulateCommand(const std::vector<std::string>& args);
int RunSlamCommand(const std::vector<std::string>& args);
int RunEvalCommand(const std::vector<std::string>& args);
int RunRunCommand(const std::vector<std::string>& args);
int RunSweepCommand(const std::vector<std::string>& args);
int RunBenchmarkCommand(const std::vector<std::string>& args);

int RunOptimizeCommand(const std::vector<std::string>& args);
int RunOdometryNoiseCommand(const std::vector<std::string>& args);
int RunWorldCommand(const std::vector<std::string>& args);

/// All subcommands, in the order `slamrig --help` lists them.
const std::vector<Command>& Commands();

/// This program's own path (/proc/self/exe), so that the runs of a study use the same build.
std::string SelfPath();

}  // namespace slamrig::app
