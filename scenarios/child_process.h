#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace slamrig::scenario {

/// A running child process of a sweep (`slamrig run`). Its stdout goes to `log_path`; its stderr
/// comes through a pipe, so that its error line reaches the sweep even when the log cannot be
/// written (a full disk), and is appended to the log when it ends.
struct Child {
  std::size_t run = 0;  ///< the caller's tag: the grid row
  std::chrono::steady_clock::time_point start;
  pid_t pid = -1;
  int stderr_fd = -1;  ///< read end of the child's stderr, non-blocking
  int stdin_fd = -1;   ///< with SpawnOptions::pipe_stdio: write end of its stdin, non-blocking
  int stdout_fd = -1;  ///< with SpawnOptions::pipe_stdio: read end of its stdout, non-blocking
  std::string log_path;
  std::string stderr_text;  ///< what it wrote there (the last 64 KiB)
  /// Past this, WaitAny kills it (SIGKILL) and sets timed_out. Never, by default.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  bool timed_out = false;
  long peak_rss_kb = 0;  ///< its peak resident memory, once it has ended (ru_maxrss)
  /// The largest VmHWM of its /proc status WaitAny saw while it ran (polled every 20 ms), of
  /// the program after exec alone. ru_maxrss also counts the copy of the parent that fork
  /// made before exec, which dwarfs a small program started by a large process.
  long polled_peak_kb = 0;
};

/// A process's VmHWM (peak resident memory since its last exec) in KiB, 0 when unknown.
long ProcessPeakKb(pid_t pid);

/// Exit code of a slamrig command that could not write its output (apps/main.cc).
inline constexpr int kExitOutputError = 74;

/// How a child ended, as far as a sweep's results are concerned.
enum class ChildEnd {
  kResult,       ///< it ran to a verdict or failed by itself: its row is recorded
  kStopped,      ///< a signal stopped it: no row, the next sweep runs it again
  kOutputError,  ///< it could not write its folder: no row, and the sweep stops
};

/// Classifies a wait status: SIGTERM, SIGINT, SIGKILL, SIGHUP (as a signal or as exit code
/// 128 + signal) come from outside; exit code kExitOutputError is an unwritable output; anything
/// else, a crash included, is the run's own result.
ChildEnd ClassifyEnd(int status);

/// The last non-empty line the child wrote to stderr, without slamrig's "slamrig: error: "
/// prefix, or `fallback`.
std::string LastErrorLine(const Child& child, const std::string& fallback);

/// Starts `args` (args[0] is the program's path) with stdout to `log_path` (truncated) and
/// stderr to a pipe. The child gets SIGTERM when the calling process dies (PR_SET_PDEATHSIG).
Child SpawnChild(const std::vector<std::string>& args, const std::string& log_path,
                 std::size_t run);

/// Where a child started by SpawnChild(args, SpawnOptions, run) writes and runs.
struct SpawnOptions {
  std::string stdout_path;  ///< truncated; its stdout
  /// Its whole stderr, truncated first; empty: a pipe, kept in Child::stderr_text and appended
  /// to stdout_path at the end (a sweep's children).
  std::string stderr_path;
  std::string working_dir;   ///< empty: this process's
  bool search_path = false;  ///< args[0] without a slash is looked up on PATH (execvp)
  bool null_stdin = false;   ///< stdin from /dev/null, else this process's
  /// Its stdin and stdout are pipes to this process (Child::stdin_fd, Child::stdout_fd; the
  /// caller closes them); stdout_path and null_stdin are then unused.
  bool pipe_stdio = false;
  /// "NAME=value" entries that the child's environment has on top of this process's (replacing
  /// a variable of the same name).
  std::vector<std::string> environment;
};

/// SpawnChild with the choices of `options`. A program that cannot be started exits with code
/// 127 and "cannot start PROGRAM: exec failed" on its stderr; a working folder it cannot enter,
/// with 127 and "cannot enter FOLDER".
Child SpawnChild(const std::vector<std::string>& args, const SpawnOptions& options,
                 std::size_t run);

/// The child processes of a sweep. However the sweep ends (done, interrupted, an error thrown),
/// the ones still running are sent SIGTERM, so that they remove their temporary files, and are
/// waited for: nothing of a stopped sweep goes on writing behind its back, and once the sweep
/// has exited no child of it is left.
class Children {
 public:
  Children() = default;
  Children(const Children&) = delete;
  Children& operator=(const Children&) = delete;
  ~Children() { StopAll(); }

  void Add(const Child& child) { running_[child.pid] = child; }
  std::size_t size() const { return running_.size(); }
  bool empty() const { return running_.empty(); }

  /// Waits until a child ends and returns it with its wait status; nullopt when none is left
  /// or SIGINT/SIGTERM arrived. A child past its deadline is killed on the way (polled every 20 ms:
  /// a signal between a check and a blocking waitpid would otherwise wait for the next child to
  /// end).
  std::optional<std::pair<Child, int>> WaitAny();

  /// SIGTERM to every running child, then waits for them (SIGKILL after 10 s).
  void StopAll();

 private:
  std::map<pid_t, Child> running_;
};

}  // namespace slamrig::scenario
