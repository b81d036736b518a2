#include "scenarios/run_queue.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "scenarios/child_process.h"
#include "scenarios/slurm_sweep.h"
#include "scenarios/sweep_summary.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"
#include "slam/types/interrupt.h"
#include "slam/types/thread_pool.h"

namespace slamrig::scenario {
namespace {

using Clock = std::chrono::steady_clock;

std::string Duration(double seconds) {
  const int s = static_cast<int>(std::lround(seconds));
  char buffer[32];
  if (s >= 3600) {
    std::snprintf(buffer, sizeof(buffer), "%d:%02d:%02d", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%d:%02d", s / 60, s % 60);
  }
  return buffer;
}

// Appends one line with a single write() and makes it durable before the next run starts.
void AppendLine(int fd, const std::string& line, const std::string& path) {
  const std::string text = line + "\n";
  if (::write(fd, text.data(), text.size()) != static_cast<ssize_t>(text.size()) ||
      ::fsync(fd) != 0) {
    throw OutputError(path + ": cannot append: " + std::strerror(errno));
  }
}

// Starts run `index` with its stdout in its folder's log.txt (stderr through a pipe, see Child).
Child SpawnRun(const RunQueueSpec& spec, const RunQueueOptions& options, std::size_t index,
               int jobs) {
  namespace fs = std::filesystem;
  const QueuedRun& run = spec.runs[index];
  fs::create_directories(run.dir);
  fs::remove(fs::path(run.dir) / "metrics.json");
  std::vector<std::string> args = {options.slamrig_binary};
  args.insert(args.end(), run.args.begin(), run.args.end());
  SpawnOptions spawn;
  spawn.stdout_path = run.dir + "/log.txt";
  // Parallel runs share the processors: each estimator's default thread count is its share,
  // unless the user chose one for all (the same results either way).
  if (std::getenv("SLAMRIG_THREADS") == nullptr) {
    spawn.environment = {"SLAMRIG_THREADS=" +
                         std::to_string(std::max(1, slam::AvailableProcessors() / jobs))};
  }
  Child child = SpawnChild(args, spawn, index);
  if (options.timeout_s > 0.0) {
    child.deadline = child.start + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(options.timeout_s));
  }
  return child;
}

RunEnd EndOf(const Child& child, int status) {
  RunEnd end;
  end.status = status;
  end.timed_out = child.timed_out;
  end.wall_s = std::chrono::duration<double>(Clock::now() - child.start).count();
  end.peak_rss_mb = static_cast<double>(child.peak_rss_kb) / 1024.0;
  end.error_line = LastErrorLine(child, "");
  return end;
}

// What an earlier, interrupted study left in results.csv.
struct ResumeState {
  bool has_header = false;       ///< the file exists with a header line
  std::set<std::string> done;    ///< run ids with a row
  std::set<std::string> failed;  ///< of them, those whose status is not pass
};

// Reads results.csv for a resumed study, which must have the same header (another is a
// ConfigError). A study killed mid-write leaves at most a partial last line: the file is cut
// back to its complete lines.
ResumeState ReadResumeState(const RunQueueSpec& spec, const std::string& csv_path) {
  namespace fs = std::filesystem;
  ResumeState state;
  if (!fs::exists(csv_path)) return state;
  std::ifstream in(csv_path, std::ios::binary);
  std::string contents((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t keep = contents.rfind('\n') == std::string::npos ? 0 : contents.rfind('\n') + 1;
  if (keep != contents.size()) fs::resize_file(csv_path, keep);
  std::istringstream lines(contents.substr(0, keep));
  std::string line;
  if (!std::getline(lines, line)) return state;
  if (SplitCsv(line) != spec.header) {
    throw ConfigError(csv_path +
                      ": written by another study (its columns differ); use another --out");
  }
  state.has_header = true;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const std::vector<std::string> fields = SplitCsv(line);
    state.done.insert(fields[0]);
    if (fields.size() <= spec.status_column || fields[spec.status_column] != "pass")
      state.failed.insert(fields[0]);
  }
  return state;
}

// The progress line: a bar, counts, elapsed time and ETA, on stderr.
class Progress {
 public:
  Progress(bool enabled, int total, int already_done)
      : enabled_(enabled), total_(total), already_done_(already_done) {}
  void Report(int finished_now, std::size_t running, int failed) const {
    if (!enabled_) return;
    const int finished = already_done_ + finished_now;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    std::string eta = "--:--";
    if (finished_now > 0) eta = Duration(elapsed / finished_now * (total_ - finished));
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? kWidth * finished / total_ : kWidth;
    const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '-');
    std::fprintf(stderr, "%s[%s] %d/%d runs, %zu running, %d failed, elapsed %s, ETA %s%s",
                 tty_ ? "\r" : "", bar.c_str(), finished, total_, running, failed,
                 Duration(elapsed).c_str(), eta.c_str(), tty_ ? "  " : "\n");
    std::fflush(stderr);
  }
  void End() const {
    if (enabled_ && tty_) std::fputc('\n', stderr);
  }

 private:
  bool enabled_;
  int total_, already_done_;
  bool tty_ = ::isatty(STDERR_FILENO) != 0;
  Clock::time_point start_ = Clock::now();
};

// The rows `todo` as one Slurm job array, appended to results.csv in order once it is over.
void RunOnSlurm(const RunQueueSpec& spec, const RunQueueOptions& options,
                const std::vector<std::size_t>& todo, int fd, const std::string& csv_path,
                RunQueueSummary* summary) {
  const std::vector<std::string> lines = RunRowsOnSlurm(options, todo);
  for (std::size_t k = 0; k < todo.size(); ++k) {
    const std::vector<std::string> fields = SplitCsv(lines[k]);
    if (lines[k].empty() || fields.size() <= spec.status_column ||
        fields[spec.status_column] != "pass") {
      ++summary->failed;
    }
    if (lines[k].empty()) {  // the task left no row: the next study runs it again
      std::fprintf(stderr, "slurm: row %zu left no result (see %s); the next run of it retries\n",
                   todo[k], SlurmTaskLogPath(options.out_dir, todo[k]).c_str());
      continue;
    }
    AppendLine(fd, lines[k], csv_path);
    ++summary->ran;
  }
}

// results.csv with its rows in the study's order (they were appended as runs ended, an order
// that depends on the machine), so that the same study gives the same file. Atomic: a study
// killed here keeps the appended file.
void SortResults(const RunQueueSpec& spec, const std::string& csv_path) {
  std::ifstream in(csv_path, std::ios::binary);
  std::string header;
  std::getline(in, header);
  std::map<std::string, std::string> by_id;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) by_id.emplace(SplitCsv(line).front(), line);
  }
  std::string text = header + "\n";
  for (const QueuedRun& run : spec.runs) {
    const auto found = by_id.find(run.id);
    if (found != by_id.end()) text += found->second + "\n";
  }
  slam::WriteFileAtomically(csv_path, text);
}

}  // namespace

std::string FormatCsvNumber(double v) {
  if (!std::isfinite(v)) return "";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", v);
  return buffer;
}

RunQueueSummary RunQueue(const RunQueueSpec& spec, const RunQueueOptions& options) {
  namespace fs = std::filesystem;
  RunQueueSummary summary;
  summary.total = static_cast<int>(spec.runs.size());
  slam::CheckOutputFolder(options.out_dir);
  fs::create_directories(fs::path(options.out_dir) / "runs");
  const std::string csv_path = (fs::path(options.out_dir) / "results.csv").string();

  const ResumeState resume = ReadResumeState(spec, csv_path);
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < spec.runs.size(); ++i) {
    if (resume.done.count(spec.runs[i].id)) {
      ++summary.already_done;
      summary.failed += static_cast<int>(resume.failed.count(spec.runs[i].id));
    } else {
      todo.push_back(i);
    }
  }
  const int fd = ::open(csv_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw OutputError(csv_path + ": cannot open: " + std::strerror(errno));
  const std::unique_ptr<int, void (*)(int*)> close_fd(new int(fd), [](int* f) {
    ::close(*f);
    delete f;
  });
  if (!resume.has_header) AppendLine(fd, JoinCsv(spec.header), csv_path);

  if (options.backend == RunBackend::kSlurm) {
    RunOnSlurm(spec, options, todo, fd, csv_path, &summary);
    SortResults(spec, csv_path);
    if (spec.summarise) spec.summarise();
    return summary;
  }

  const int jobs = options.jobs > 0 ? options.jobs : slam::AvailableProcessors();
  Children running;
  std::size_t next = 0;
  int finished_now = 0;
  const Progress progress(options.progress, summary.total, summary.already_done);
  while (next < todo.size() || !running.empty()) {
    while (next < todo.size() && static_cast<int>(running.size()) < jobs && InterruptSignal() == 0)
      running.Add(SpawnRun(spec, options, todo[next++], jobs));
    // Said once the freed slots are filled again, so "running" is what runs.
    progress.Report(finished_now, running.size(), summary.failed);
    const auto ended = running.WaitAny();
    // SIGINT/SIGTERM: `running` stops the children on the way out, and their rows stay missing.
    ThrowIfInterrupted();
    if (!ended) break;
    const Child& child = ended->first;
    const std::string& run_dir = spec.runs[child.run].dir;
    switch (child.timed_out ? ChildEnd::kResult : ClassifyEnd(ended->second)) {
      case ChildEnd::kStopped:
        ++summary.failed;
        std::fprintf(stderr, "%s: stopped by a signal; the next run of the study runs it again\n",
                     run_dir.c_str());
        continue;
      case ChildEnd::kOutputError:
        // The disk is full or the folder read-only: every other run would fail the same way.
        throw OutputError(LastErrorLine(child, run_dir + ": the run could not write its output"));
      case ChildEnd::kResult:
        break;
    }
    bool passed = false;
    const std::vector<std::string> row = spec.row(child.run, EndOf(child, ended->second), &passed);
    if (!passed) ++summary.failed;
    AppendLine(fd, JoinCsv(row), csv_path);
    ++finished_now;
    ++summary.ran;
  }
  progress.Report(finished_now, running.size(), summary.failed);
  progress.End();
  SortResults(spec, csv_path);
  if (spec.summarise) spec.summarise();
  return summary;
}

bool RunQueueRow(const RunQueueSpec& spec, const RunQueueOptions& options, std::size_t row) {
  Children running;
  running.Add(SpawnRun(spec, options, row, /*jobs=*/1));
  const auto ended = running.WaitAny();
  // scancel: SIGTERM to the task and its child; no row file, so a resumed study runs it again.
  ThrowIfInterrupted();
  if (!ended) throw std::runtime_error("waitpid: " + std::string(std::strerror(errno)));
  const Child& child = ended->first;
  const std::string& run_dir = spec.runs[row].dir;
  switch (child.timed_out ? ChildEnd::kResult : ClassifyEnd(ended->second)) {
    case ChildEnd::kStopped:
      throw std::runtime_error(run_dir + ": stopped by a signal; its row is not written");
    case ChildEnd::kOutputError:
      throw OutputError(LastErrorLine(child, run_dir + ": the run could not write its output"));
    case ChildEnd::kResult:
      break;
  }
  bool passed = false;
  const std::vector<std::string> fields = spec.row(row, EndOf(child, ended->second), &passed);
  const std::string path = QueueRowPath(options.out_dir, row);
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  slam::WriteFileAtomically(path, JoinCsv(spec.header) + "\n" + JoinCsv(fields) + "\n");
  return passed;
}

std::string QueueRowPath(const std::string& out_dir, std::size_t row) {
  char name[32];
  std::snprintf(name, sizeof(name), "%04zu.csv", row);
  return (std::filesystem::path(out_dir) / "rows" / name).string();
}

}  // namespace slamrig::scenario
