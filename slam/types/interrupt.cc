#include "slam/types/interrupt.h"

#include <signal.h>

#include <csignal>

namespace slamrig {
namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void RecordSignal(int signal) {
  // The first signal wins: a second Ctrl-C while stopping does not change the exit code.
  if (g_signal == 0) g_signal = signal;
}

}  // namespace

Interrupted::Interrupted(int signal)
    : std::runtime_error("interrupted by " + SignalName(signal)), signal_(signal) {}

void InstallInterruptHandlers() {
  struct sigaction action = {};
  action.sa_handler = RecordSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: waitpid and sleeps return EINTR
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int InterruptSignal() { return static_cast<int>(g_signal); }

void ThrowIfInterrupted() {
  if (const int signal = InterruptSignal(); signal != 0) throw Interrupted(signal);
}

std::string SignalName(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace slamrig
