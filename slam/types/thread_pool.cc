#include "slam/types/thread_pool.h"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <system_error>

#include "slam/types/check.h"
#include "slam/types/error.h"

namespace slamrig::slam {
namespace {

// Block `k` of `parts` over [0, n).
std::pair<int, int> Block(int n, int parts, int k) {
  const long begin = static_cast<long>(n) * k / parts;
  const long end = static_cast<long>(n) * (k + 1) / parts;
  return {static_cast<int>(begin), static_cast<int>(end)};
}

}  // namespace

int AvailableProcessors() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(0, sizeof(set), &set) == 0) return std::max(1, CPU_COUNT(&set));
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

int DefaultThreadCount() {
  if (const char* text = std::getenv("SLAMRIG_THREADS"); text != nullptr) {
    int value = 0;
    const char* end = text + std::strlen(text);
    const auto [ptr, error] = std::from_chars(text, end, value);
    if (error != std::errc() || ptr != end || value < 1 || value > 1024) {
      throw ConfigError(std::string("SLAMRIG_THREADS=") + text +
                        ": must be a whole number from 1 to 1024 (the threads of threads: 0)");
    }
    return value;
  }
  return AvailableProcessors();
}

int ThreadCount(int requested) { return requested >= 1 ? requested : DefaultThreadCount(); }

void RunTasks(std::span<const std::function<void()>> tasks, int max_threads) {
  std::vector<std::exception_ptr> errors(tasks.size());
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t i = next++; i < tasks.size(); i = next++) {
      try {
        tasks[i]();
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  const std::size_t threads_wanted =
      std::min(tasks.size(), static_cast<std::size_t>(std::max(1, max_threads)));
  std::vector<std::thread> threads;
  for (std::size_t t = 1; t < threads_wanted; ++t) {
    try {
      threads.emplace_back(work);
    } catch (const std::system_error&) {
      break;  // no thread to be had: the ones started and the caller do the rest
    }
  }
  work();
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

BackgroundWorker::BackgroundWorker(bool threaded) {
  if (threaded) thread_ = std::thread([this] { Loop(); });
}

BackgroundWorker::~BackgroundWorker() {
  if (!thread_.joinable()) return;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !busy_; });
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void BackgroundWorker::Start(std::function<void()> task) {
  if (!thread_.joinable()) {
    task();
    return;
  }
  Wait();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    task_ = std::move(task);
    busy_ = true;
  }
  changed_.notify_all();
}

void BackgroundWorker::Wait() {
  if (!thread_.joinable()) return;
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !busy_; });
    std::swap(error, error_);
  }
  if (error) std::rethrow_exception(error);
}

void BackgroundWorker::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return busy_ || stop_; });
    if (!busy_) return;  // stopped, and nothing in hand
    std::function<void()> task = std::move(task_);
    lock.unlock();
    std::exception_ptr error;
    try {
      task();
    } catch (...) {
      error = std::current_exception();
    }
    task = nullptr;  // what it holds is released before the caller hears that it ended
    lock.lock();
    error_ = error;
    busy_ = false;
    changed_.notify_all();
  }
}

ThreadPool::ThreadPool(int num_threads) {
  SLAMRIG_CHECK(num_threads >= 1, "ThreadPool needs at least one thread");
  for (int i = 1; i < num_threads; ++i) workers_.emplace_back([this, i] { WorkerLoop(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void ThreadPool::ParallelFor(int n, const std::function<void(int, int)>& body) {
  if (workers_.empty() || n <= 1) {
    if (n > 0) body(0, n);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    body_ = &body;
    n_ = n;
    pending_ = static_cast<int>(workers_.size());
    ++generation_;
  }
  start_.notify_all();
  const auto [begin, end] = Block(n, num_threads(), 0);
  if (begin < end) body(begin, end);
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return pending_ == 0; });
  body_ = nullptr;
}

void ThreadPool::WorkerLoop(int worker_index) {
  std::uint64_t seen = 0;
  while (true) {
    const std::function<void(int, int)>* body;
    int n;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      body = body_;
      n = n_;
    }
    const auto [begin, end] = Block(n, num_threads(), worker_index);
    if (begin < end) (*body)(begin, end);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --pending_;
    }
    done_.notify_one();
  }
}

}  // namespace slamrig::slam
