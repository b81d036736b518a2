#pragma once

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

namespace slamrig::slam {

/// The processors this process may run on: its CPU affinity (all of a workstation's, a Slurm
/// task's allocation, a taskset's), at least 1.
int AvailableProcessors();

/// The threads that a `threads: 0` setting (the pf's and the rbpf's default) runs on:
/// SLAMRIG_THREADS when it is set (a whole number from 1 to 1024; the run queue sets it so that
/// its parallel runs share the machine), else AvailableProcessors(). Throws ConfigError
/// naming SLAMRIG_THREADS when its value is not such a number.
int DefaultThreadCount();

/// `requested` when it is >= 1, else DefaultThreadCount().
int ThreadCount(int requested);

/// Runs every task once, on up to `max_threads` threads (the caller's among them), and returns
/// when all have ended. The tasks must be independent: which thread runs which never changes a
/// result. When tasks throw, the exception of the first of them (in order) is rethrown here, after
/// every task has ended.
void RunTasks(std::span<const std::function<void()>> tasks, int max_threads);

/// One thread of its own that runs one task at a time beside the caller: Start hands it a task
/// (after the one in hand has ended), Wait returns when that task has ended and rethrows what it
/// threw. Kept for the object's life, so a task per scan costs a wake-up, not a thread.
/// Without a thread (`threaded` false, as one processor asks) Start runs the task in the caller
/// at once (what it throws comes out of Start) and Wait has nothing to wait for.
class BackgroundWorker {
 public:
  explicit BackgroundWorker(bool threaded = true);
  /// Waits for the task in hand (what it threw is dropped), then ends the thread.
  ~BackgroundWorker();
  BackgroundWorker(const BackgroundWorker&) = delete;
  BackgroundWorker& operator=(const BackgroundWorker&) = delete;

  void Start(std::function<void()> task);
  void Wait();

 private:
  void Loop();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> task_;
  bool busy_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

/// A fixed set of worker threads for data-parallel loops. `ParallelFor` splits [0, n) into one
/// contiguous block per thread (the caller runs the first) and returns when all are done. Which
/// thread runs which index never changes a result as long as iterations are independent.
class ThreadPool {
 public:
  /// `num_threads` >= 1 counts the calling thread; 1 runs everything inline.
  explicit ThreadPool(int num_threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls `body(begin, end)` on disjoint blocks covering [0, n).
  void ParallelFor(int n, const std::function<void(int begin, int end)>& body);

 private:
  void WorkerLoop(int worker_index);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  const std::function<void(int, int)>* body_ = nullptr;
  int n_ = 0;
  std::uint64_t generation_ = 0;
  int pending_ = 0;
  bool stop_ = false;
};

}  // namespace slamrig::slam
