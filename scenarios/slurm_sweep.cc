#include "scenarios/slurm_sweep.h"

#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "slam/io/atomic_file.h"
#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

// `text` as one single-quoted shell word.
std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout
};

// Runs a shell command line and collects its stdout (stderr goes to ours).
CommandResult Run(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run: " + command);
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// The data line of a row file (its second line), or "" when absent or incomplete.
std::string RowLine(const std::string& path) {
  std::ifstream in(path);
  std::string header, line;
  if (!std::getline(in, header) || !std::getline(in, line)) return "";
  return line;
}

}  // namespace

std::string SlurmTaskLogPath(const std::string& out_dir, std::size_t row) {
  return (fs::path(out_dir) / "slurm" / ("task_" + std::to_string(row) + ".log")).string();
}

std::string SlurmArrayIndices(const std::vector<std::size_t>& rows) {
  std::string out;
  for (std::size_t i = 0; i < rows.size();) {
    std::size_t j = i;
    while (j + 1 < rows.size() && rows[j + 1] == rows[j] + 1) ++j;
    if (!out.empty()) out += ",";
    out += std::to_string(rows[i]);
    if (j > i) out += "-" + std::to_string(rows[j]);
    i = j + 1;
  }
  return out;
}

std::vector<std::string> RunRowsOnSlurm(const RunQueueOptions& options,
                                        const std::vector<std::size_t>& rows) {
  if (rows.empty()) return {};
  const fs::path out = fs::absolute(options.out_dir);
  const fs::path slurm_dir = out / "slurm";
  fs::create_directories(slurm_dir);
  // A row file left by an earlier attempt would pass for this one's result.
  for (const std::size_t row : rows) fs::remove(QueueRowPath(out.string(), row));

  const std::string script = (slurm_dir / (options.command + ".sbatch")).string();
  slam::WriteFileAtomically(script, "#!/bin/sh\n# One row per array task (written by slamrig " +
                                        options.command + " --backend slurm).\nexec " +
                                        ShellQuote(options.slamrig_binary) + " " + options.command +
                                        " " + ShellQuote(fs::absolute(options.spec_path).string()) +
                                        " --out " + ShellQuote(out.string()) +
                                        " --row \"$SLURM_ARRAY_TASK_ID\" --quiet\n");
  const std::string submit = "sbatch --parsable --job-name=slamrig-" + options.command +
                             " --array=" + SlurmArrayIndices(rows) +
                             " --output=" + ShellQuote((slurm_dir / "task_%a.log").string()) + " " +
                             ShellQuote(script);
  const CommandResult submitted = Run(submit);
  const std::string job = submitted.output.substr(0, submitted.output.find_first_of(";\n"));
  if (submitted.exit_code != 0 || job.empty()) {
    throw std::runtime_error("sbatch failed (exit " + std::to_string(submitted.exit_code) +
                             "): " + submit);
  }
  if (options.progress) {
    std::fprintf(stderr, "slurm: job %s, %zu tasks (array %s)\n", job.c_str(), rows.size(),
                 SlurmArrayIndices(rows).c_str());
  }

  // Follow the job until squeue lists none of its tasks (or no longer knows the job).
  auto queued = [&job] {
    const CommandResult queue = Run("squeue -h -j " + job + " -o %i 2>/dev/null");
    return queue.exit_code == 0 && queue.output.find_first_not_of(" \n") != std::string::npos;
  };
  std::size_t last_done = 0;
  while (true) {
    // Asked before the signal check: Ctrl-C reaches squeue too, which then fails as if the job
    // were gone.
    const bool still_queued = queued();
    if (const int signal = InterruptSignal(); signal != 0) {
      // Ctrl-C: the tasks must not go on running rows nobody waits for.
      const CommandResult cancel = Run("scancel " + job);
      std::fprintf(stderr, "slurm: %s job %s\n",
                   cancel.exit_code == 0 ? "cancelled" : "could not cancel (scancel failed)",
                   job.c_str());
      for (int i = 0; i < 60 && cancel.exit_code == 0 && queued(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
      throw Interrupted(signal);
    }
    if (!still_queued) break;
    if (options.progress) {
      std::size_t done = 0;
      for (const std::size_t row : rows)
        done += fs::exists(QueueRowPath(out.string(), row)) ? 1 : 0;
      if (done != last_done) std::fprintf(stderr, "slurm: %zu/%zu rows\n", done, rows.size());
      last_done = done;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }

  std::vector<std::string> lines;
  for (const std::size_t row : rows) lines.push_back(RowLine(QueueRowPath(out.string(), row)));
  return lines;
}

}  // namespace slamrig::scenario
