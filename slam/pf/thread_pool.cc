#include "slam/pf/thread_pool.h"

#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// Block `k` of `parts` over [0, n).
std::pair<int, int> Block(int n, int parts, int k) {
  const long begin = static_cast<long>(n) * k / parts;
  const long end = static_cast<long>(n) * (k + 1) / parts;
  return {static_cast<int>(begin), static_cast<int>(end)};
}

}  // namespace

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
