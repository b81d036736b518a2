#include "scenarios/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

using Clock = std::chrono::steady_clock;

// Reads what is there on the child's stderr pipe; closes it at end of file.
void DrainStderr(Child* child) {
  char buffer[4096];
  while (child->stderr_fd >= 0) {
    const ssize_t n = ::read(child->stderr_fd, buffer, sizeof(buffer));
    if (n > 0) {
      child->stderr_text.append(buffer, static_cast<std::size_t>(n));
      constexpr std::size_t kKeep = 64 * 1024;
      if (child->stderr_text.size() > kKeep)
        child->stderr_text.erase(0, child->stderr_text.size() - kKeep);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    ::close(child->stderr_fd);  // end of file, or an error: nothing more will come
    child->stderr_fd = -1;
  }
}

// A child that ended: the rest of its stderr, appended to its log.txt (best effort: the disk
// may be full; the text stays in `child` for the sweep's error line).
void FinishChild(Child* child) {
  // Only the child held the pipe's write end (O_CLOEXEC elsewhere), so end of file is near; a
  // deadline all the same, should a process it started keep the pipe open.
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(2);
  while (child->stderr_fd >= 0 && Clock::now() < deadline) {
    DrainStderr(child);
    if (child->stderr_fd >= 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (child->stderr_fd >= 0) {
    ::close(child->stderr_fd);
    child->stderr_fd = -1;
  }
  if (child->stderr_text.empty()) return;
  std::ofstream log(child->log_path, std::ios::app | std::ios::binary);
  log << child->stderr_text;
}

// Closes both ends of each pipe that is open, and marks them closed.
void ClosePairs(std::initializer_list<int*> pairs) {
  for (int* pair : pairs) {
    for (int i = 0; i < 2; ++i) {
      if (pair[i] >= 0) ::close(pair[i]);
      pair[i] = -1;
    }
  }
}

// In the child between fork and exec (async-signal-safe calls only): its stdin, stdout and
// stderr as `options` say; the pipe ends given are the child's (dup2 clears O_CLOEXEC on the
// copy).
void RedirectStdio(const SpawnOptions& options, int stderr_write, int stdin_read,
                   int stdout_write) {
  if (options.pipe_stdio) {
    ::dup2(stdin_read, STDIN_FILENO);
    ::dup2(stdout_write, STDOUT_FILENO);
  } else {
    const int log = ::open(options.stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (log >= 0) ::dup2(log, STDOUT_FILENO);
    if (options.null_stdin) {
      const int null = ::open("/dev/null", O_RDONLY);
      if (null >= 0) ::dup2(null, STDIN_FILENO);
    }
  }
  if (options.stderr_path.empty()) {
    ::dup2(stderr_write, STDERR_FILENO);
  } else {
    const int err = ::open(options.stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (err >= 0) ::dup2(err, STDERR_FILENO);
  }
}

}  // namespace

ChildEnd ClassifyEnd(int status) {
  if (WIFSIGNALED(status)) {
    const int s = WTERMSIG(status);
    // A crash is the run's own failure; these come from outside (a user, scancel, the OOM killer).
    return s == SIGTERM || s == SIGINT || s == SIGKILL || s == SIGHUP ? ChildEnd::kStopped
                                                                      : ChildEnd::kResult;
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 0;
  if (code == 128 + SIGINT || code == 128 + SIGTERM) return ChildEnd::kStopped;
  if (code == kExitOutputError) return ChildEnd::kOutputError;
  return ChildEnd::kResult;
}

// The last non-empty line a child wrote to stderr (its error line, without slamrig's prefix),
// or `fallback`.
std::string LastErrorLine(const Child& child, const std::string& fallback) {
  std::istringstream in(child.stderr_text);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  const std::string prefix = "slamrig: error: ";
  if (last.rfind(prefix, 0) == 0) last = last.substr(prefix.size());
  return last.empty() ? fallback : last;
}

Child SpawnChild(const std::vector<std::string>& args, const std::string& log_path,
                 std::size_t run) {
  SpawnOptions options;
  options.stdout_path = log_path;
  return SpawnChild(args, options, run);
}

Child SpawnChild(const std::vector<std::string>& args, const SpawnOptions& options,
                 std::size_t run) {
  Child child;
  child.run = run;
  child.start = Clock::now();
  child.log_path = options.stdout_path;
  // Everything the child needs is made before fork: between fork and exec it only calls
  // async-signal-safe functions.
  std::vector<std::string> argv_text = args;
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The child's environment: this process's, with `options.environment` on top.
  std::vector<std::string> env_text = options.environment;
  std::vector<char*> envp;
  if (!options.environment.empty()) {
    auto overridden = [&](std::string_view entry) {
      const std::string_view name = entry.substr(0, entry.find('='));
      return std::any_of(
          options.environment.begin(), options.environment.end(),
          [&](const std::string& e) { return std::string_view(e).substr(0, e.find('=')) == name; });
    };
    for (char** e = environ; *e != nullptr; ++e) {
      if (!overridden(*e)) envp.push_back(*e);
    }
    for (auto& e : env_text) envp.push_back(e.data());
    envp.push_back(nullptr);
  }
  char** const child_environ = options.environment.empty() ? environ : envp.data();
  const std::string exec_failed =
      "cannot start " + (args.empty() ? std::string() : args.front()) + ": exec failed\n";
  const std::string chdir_failed = "cannot enter " + options.working_dir + "\n";
  const bool to_pipe = options.stderr_path.empty();
  int pipe_fds[2] = {-1, -1};
  if (to_pipe && ::pipe2(pipe_fds, O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("pipe failed: ") + std::strerror(errno));
  // stdin and stdout pipes: [0] read end, [1] write end, close-on-exec in this process (so no
  // other child holds them open), made the child's 0 and 1 by dup2.
  int in_fds[2] = {-1, -1}, out_fds[2] = {-1, -1};
  if (options.pipe_stdio && (::pipe2(in_fds, O_CLOEXEC) != 0 || ::pipe2(out_fds, O_CLOEXEC) != 0)) {
    const int error = errno;
    ClosePairs({pipe_fds, in_fds, out_fds});
    throw std::runtime_error(std::string("pipe failed: ") + std::strerror(error));
  }
  // Closed by the exec (or the child's exit): once it reads end of file, what runs in the child
  // is the program, not this process's copy (whose memory the child's /proc status would show).
  int exec_fds[2] = {-1, -1};
  if (::pipe2(exec_fds, O_CLOEXEC) != 0) {
    ClosePairs({pipe_fds, in_fds, out_fds});
    throw std::runtime_error(std::string("pipe failed: ") + std::strerror(errno));
  }
  // SIGINT and SIGTERM blocked across fork: the child starts with this process's handlers, which
  // only record a signal in the child's copy of memory, lost at exec. Blocked, a signal sent to
  // the child before it restores the default action stays pending and then ends it.
  sigset_t interrupts, old_mask;
  sigemptyset(&interrupts);
  sigaddset(&interrupts, SIGINT);
  sigaddset(&interrupts, SIGTERM);
  ::sigprocmask(SIG_BLOCK, &interrupts, &old_mask);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    ::sigprocmask(SIG_SETMASK, &old_mask, nullptr);
    // A child never outlives a killed sweep: it would finish a run nobody records. SIGTERM
    // (not SIGKILL), so that it still removes its temporary files.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(128 + SIGTERM);  // the sweep died before prctl
    RedirectStdio(options, pipe_fds[1], in_fds[0], out_fds[1]);
    const auto fail = [](const std::string& message) {
      [[maybe_unused]] const ssize_t written =
          ::write(STDERR_FILENO, message.data(), message.size());
      ::_exit(127);
    };
    if (!options.working_dir.empty() && ::chdir(options.working_dir.c_str()) != 0)
      fail(chdir_failed);
    if (options.search_path) {
      ::execvpe(argv[0], argv.data(), child_environ);
    } else {
      ::execve(argv[0], argv.data(), child_environ);
    }
    fail(exec_failed);
  }
  const int fork_errno = errno;
  ::sigprocmask(SIG_SETMASK, &old_mask, nullptr);
  ::close(exec_fds[1]);
  if (pid > 0) {
    char byte = 0;
    while (::read(exec_fds[0], &byte, 1) < 0 && errno == EINTR) {
    }
  }
  ::close(exec_fds[0]);
  if (pid < 0) {
    ClosePairs({pipe_fds, in_fds, out_fds});
    throw std::runtime_error(std::string("fork failed: ") + std::strerror(fork_errno));
  }
  if (options.pipe_stdio) {
    ::close(in_fds[0]);
    ::close(out_fds[1]);
    ::fcntl(in_fds[1], F_SETFL, O_NONBLOCK);
    ::fcntl(out_fds[0], F_SETFL, O_NONBLOCK);
    // A larger pipe means fewer wake-ups per scan; the default (64 KiB) works too.
    ::fcntl(in_fds[1], F_SETPIPE_SZ, 1 << 20);
    child.stdin_fd = in_fds[1];
    child.stdout_fd = out_fds[0];
  }
  if (to_pipe) {
    ::close(pipe_fds[1]);
    ::fcntl(pipe_fds[0], F_SETFL, O_NONBLOCK);
    child.stderr_fd = pipe_fds[0];
  }
  child.pid = pid;
  return child;
}

long ProcessPeakKb(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  }
  return 0;
}

std::optional<std::pair<Child, int>> Children::WaitAny() {
  while (!running_.empty() && InterruptSignal() == 0) {
    const Clock::time_point now = Clock::now();
    for (auto& [pid, child] : running_) {
      DrainStderr(&child);
      child.polled_peak_kb = std::max(child.polled_peak_kb, ProcessPeakKb(pid));
      if (!child.timed_out && now > child.deadline) {
        child.timed_out = true;
        ::kill(pid, SIGKILL);
      }
    }
    int status = 0;
    struct rusage usage {};
    const pid_t pid = ::wait4(-1, &status, WNOHANG, &usage);
    if (pid < 0 && errno != EINTR) return std::nullopt;
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    const auto it = running_.find(pid);
    if (it == running_.end()) continue;
    Child child = std::move(it->second);
    running_.erase(it);
    child.peak_rss_kb = usage.ru_maxrss;
    FinishChild(&child);
    return std::make_pair(std::move(child), status);
  }
  return std::nullopt;
}

void Children::StopAll() {
  for (const auto& [pid, child] : running_) ::kill(pid, SIGTERM);
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(10);
  while (!running_.empty()) {
    for (auto& [pid, child] : running_) DrainStderr(&child);
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      if (const auto it = running_.find(pid); it != running_.end()) {
        FinishChild(&it->second);
        running_.erase(it);
      }
    } else if (pid < 0 && errno == ECHILD) {
      break;
    } else if (Clock::now() > deadline) {
      for (const auto& [p, child] : running_) ::kill(p, SIGKILL);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  for (auto& [pid, child] : running_) {
    if (child.stderr_fd >= 0) ::close(child.stderr_fd);
  }
  running_.clear();
}

}  // namespace slamrig::scenario
