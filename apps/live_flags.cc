#include "apps/live_flags.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "slam/types/error.h"

namespace slamrig::app {
namespace {

// How long the clients may take, after the run, to receive what is queued for them.
constexpr double kDrainS = 3.0;

bool AllDigits(const std::string& s) {
  if (s.empty() || s.size() > 18) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

void TakeLivePort(std::vector<std::string>* args, LiveFlags* flags) {
  for (std::size_t i = 0; i < args->size(); ++i) {
    std::string& a = (*args)[i];
    if (a == "--") break;
    if (a.starts_with("--live=")) {
      flags->port = a.substr(7);
      a = "--live";
      if (flags->port.empty()) flags->port = "''";  // refused by StartLive
    } else if (a == "--live" && i + 1 < args->size() && AllDigits((*args)[i + 1])) {
      flags->port = (*args)[i + 1];
      args->erase(args->begin() + static_cast<std::ptrdiff_t>(i) + 1);
    }
  }
}

void AddLiveFlags(ArgParser* parser, LiveFlags* flags) {
  parser->AddFlag("live",
                  "[PORT] serve the run as it happens over the Foxglove WebSocket protocol on "
                  "ws://127.0.0.1:PORT (default 8765; 0 picks a free port) for Foxglove "
                  "(docs/foxglove.md)",
                  &flags->live);
  parser->AddOption("live-pace", "F",
                    "with --live, the run's speed while a client is subscribed: 1 real time, 2 "
                    "twice as fast, 0 as fast as it goes; a client changes it with the "
                    "slamrig.pace parameter [default: 1]",
                    &flags->pace);
  parser->AddFlag("live-wait",
                  "with --live, hold the run at its start until a client subscribes to a topic, "
                  "so that a viewer opened after the command sees the whole run",
                  &flags->wait);
}

std::unique_ptr<scenario::LiveServer> StartLive(const std::string& command, const LiveFlags& flags,
                                                scenario::RunnerOptions* options) {
  if (!flags.live) {
    if (!flags.pace.empty()) throw ConfigError(command + ": --live-pace needs --live");
    if (flags.wait) throw ConfigError(command + ": --live-wait needs --live");
    return nullptr;
  }
  scenario::LiveOptions live;
  if (!flags.port.empty()) {
    const long port = AllDigits(flags.port) ? std::stol(flags.port) : -1;
    if (port < 0 || port > 65535) {
      throw ConfigError(command +
                        ": --live: expected a port number 0..65535 (0 picks a free one), "
                        "got " +
                        flags.port);
    }
    live.port = static_cast<std::uint16_t>(port);
  }
  if (!flags.pace.empty()) {
    char* end = nullptr;
    const double pace = std::strtod(flags.pace.c_str(), &end);
    if (end != flags.pace.c_str() + flags.pace.size() || !std::isfinite(pace) || pace < 0.0) {
      throw ConfigError(command + ": --live-pace: expected a number >= 0 (0 as fast as it goes, " +
                        "1 real time), got '" + flags.pace + "'");
    }
    live.pace = pace;
  }
  live.wait_for_watcher = flags.wait;
  auto server = std::make_unique<scenario::LiveServer>(live);
  scenario::LiveServer* s = server.get();
  options->live = s;
  options->pace = [s](Time t) { s->Pace(t); };
  std::fprintf(stderr, "live: Foxglove WebSocket on %s (Foxglove: Open connection)\n",
               s->url().c_str());
  if (flags.wait) std::fprintf(stderr, "live: the run starts when a client subscribes\n");
  std::fflush(stderr);
  return server;
}

void FinishLive(scenario::LiveServer* live, bool quiet) {
  if (!live) return;
  live->Close(kDrainS);
  const scenario::LiveStats stats = live->stats();
  if (!quiet || stats.dropped > 0) {
    std::fprintf(stderr, "live: %llu clients, %llu messages sent, %llu dropped (a full queue)\n",
                 static_cast<unsigned long long>(stats.clients),
                 static_cast<unsigned long long>(stats.sent),
                 static_cast<unsigned long long>(stats.dropped));
  }
}

}  // namespace slamrig::app
