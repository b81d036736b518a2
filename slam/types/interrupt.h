#pragma once

#include <stdexcept>
#include <string>

namespace slamrig {

/// SIGINT or SIGTERM arrived: the work stops where it stands. Thrown by ThrowIfInterrupted from
/// the loops that check it (simulation steps, scans, report files, a sweep's waits), so that
/// the stack unwinds, writers remove their temporary files and no partial output is renamed
/// into place. main turns it into one line and exit code 128 + signal.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal);
  /// SIGINT or SIGTERM.
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// Installs handlers for SIGINT and SIGTERM that only record the signal (async-signal-safe).
/// Without SA_RESTART: a blocking wait returns EINTR, so a loop around it sees the flag at
/// once. Called once, first thing in main.
void InstallInterruptHandlers();

/// The signal received since InstallInterruptHandlers (SIGINT or SIGTERM), or 0.
int InterruptSignal();

/// Throws Interrupted when a signal was received; cheap (one load), for hot loops.
void ThrowIfInterrupted();

/// "SIGINT", "SIGTERM", or "signal N".
std::string SignalName(int signal);

}  // namespace slamrig
