#pragma once

#include <memory>
#include <string>
#include <vector>

#include "apps/cli_args.h"
#include "scenarios/live_server.h"
#include "scenarios/scenario_runner.h"

namespace slamrig::app {

/// `--live [PORT]`, `--live-pace F` and `--live-wait` of `slamrig run` and `slamrig slam`.
struct LiveFlags {
  bool live = false;
  bool wait = false;  ///< hold the run until a client subscribes
  std::string port;   ///< as typed after --live; empty: the default port
  std::string pace;   ///< as typed after --live-pace; empty: real time
};

/// Takes the optional PORT of `--live PORT` (a number right after --live) or `--live=PORT` out of
/// `args` into `flags->port`, leaving a plain `--live` for the parser.
void TakeLivePort(std::vector<std::string>* args, LiveFlags* flags);

/// Declares --live, --live-pace and --live-wait on `parser`.
void AddLiveFlags(ArgParser* parser, LiveFlags* flags);

/// The live view the flags ask for, listening before the run starts, or nullptr; sets
/// `options->live` and `options->pace` to it and says its address on stderr. Throws ConfigError
/// for a bad PORT or pace (or --live-pace or --live-wait without --live), OutputError when it
/// cannot listen (the port in use).
std::unique_ptr<scenario::LiveServer> StartLive(const std::string& command, const LiveFlags& flags,
                                                scenario::RunnerOptions* options);

/// After the run: lets the clients receive what is queued (a few seconds at most), closes the
/// server and says what it sent and dropped on stderr unless `quiet`.
void FinishLive(scenario::LiveServer* live, bool quiet);

}  // namespace slamrig::app
