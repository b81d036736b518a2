#include "slam/types/thread_pool.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "slam/types/error.h"
#include "tests/util/scoped_env.h"

namespace slamrig::slam {
namespace {

TEST(ThreadPoolTest, ParallelForVisitsEveryIndexExactlyOnce) {
  for (const int threads : {1, 2, 3, 8}) {
    ThreadPool pool(threads);
    for (const int n : {0, 1, 2, 5, 100, 1001}) {
      std::vector<std::atomic<int>> hits(static_cast<std::size_t>(n));
      for (int round = 0; round < 3; ++round) {
        pool.ParallelFor(n, [&](int begin, int end) {
          for (int i = begin; i < end; ++i) hits[static_cast<std::size_t>(i)]++;
        });
      }
      for (int i = 0; i < n; ++i)
        ASSERT_EQ(hits[static_cast<std::size_t>(i)].load(), 3) << threads << " " << n;
    }
  }
}

TEST(ThreadPoolTest, RunTasksRunsEachTaskOnceAndRethrowsTheFirstFailure) {
  for (const int threads : {0, 1, 2, 3, 8}) {
    for (const int n : {0, 1, 2, 5, 40}) {
      std::vector<std::atomic<int>> hits(static_cast<std::size_t>(n));
      std::vector<std::function<void()>> tasks;
      for (int i = 0; i < n; ++i)
        tasks.push_back([&hits, i] { hits[static_cast<std::size_t>(i)]++; });
      RunTasks(tasks, threads);
      for (int i = 0; i < n; ++i) ASSERT_EQ(hits[static_cast<std::size_t>(i)].load(), 1) << threads;
    }
    // Tasks 3 and 7 of 10 throw: every task still runs, and task 3's error is the one rethrown.
    std::vector<std::atomic<int>> hits(10);
    std::vector<std::function<void()>> tasks;
    for (int i = 0; i < 10; ++i) {
      tasks.push_back([&hits, i] {
        hits[static_cast<std::size_t>(i)]++;
        if (i == 3 || i == 7) throw std::runtime_error("task " + std::to_string(i));
      });
    }
    try {
      RunTasks(tasks, threads);
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "task 3");
    }
    for (const std::atomic<int>& h : hits) EXPECT_EQ(h.load(), 1);
  }
}

// The worker runs its tasks one at a time in the order given, each after the caller's Start and
// before its Wait returns; a task's exception comes back from the next Wait (or Start), once.
TEST(ThreadPoolTest, ABackgroundWorkerRunsItsTasksInOrderAndRethrows) {
  BackgroundWorker worker;
  std::vector<int> order;
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<bool> elsewhere{true};
  for (int i = 0; i < 200; ++i) {
    worker.Start([&, i] {
      order.push_back(i);
      elsewhere = elsewhere && std::this_thread::get_id() != caller;
    });
  }
  worker.Wait();
  ASSERT_EQ(order.size(), 200u);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(order[static_cast<std::size_t>(i)], i);
  EXPECT_TRUE(elsewhere.load());

  worker.Start([] { throw std::runtime_error("back end"); });
  try {
    worker.Wait();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "back end");
  }
  worker.Wait();  // said once
  worker.Start([] { throw std::runtime_error("second"); });
  EXPECT_THROW(worker.Start([] {}), std::runtime_error);  // Start waits for the one in hand
  worker.Wait();

  // Without a thread: each task runs in the caller, at once, and its error comes out of Start.
  BackgroundWorker inline_worker(false);
  std::thread::id ran_on;
  inline_worker.Start([&] { ran_on = std::this_thread::get_id(); });
  EXPECT_EQ(ran_on, caller);
  EXPECT_THROW(inline_worker.Start([] { throw std::runtime_error("inline"); }), std::runtime_error);
  inline_worker.Wait();  // nothing in hand

  // The destructor waits for the task in hand.
  std::atomic<bool> done{false};
  {
    BackgroundWorker w;
    w.Start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      done = true;
    });
  }
  EXPECT_TRUE(done.load());
}

// The default thread count: the processors of this process's affinity, or SLAMRIG_THREADS when
// set; a bad SLAMRIG_THREADS is a ConfigError that names it.
TEST(ThreadPoolTest, ThreadsZeroMeansTheProcessorsOrSlamrigThreads) {
  const testing::ScopedEnv threads("SLAMRIG_THREADS", nullptr);
  cpu_set_t set;
  CPU_ZERO(&set);
  ASSERT_EQ(::sched_getaffinity(0, sizeof(set), &set), 0);
  EXPECT_EQ(AvailableProcessors(), CPU_COUNT(&set));
  EXPECT_EQ(ThreadCount(0), CPU_COUNT(&set));
  EXPECT_EQ(ThreadCount(3), 3);
  threads.Set("5");
  EXPECT_EQ(ThreadCount(0), 5);
  EXPECT_EQ(ThreadCount(2), 2);
  for (const char* bad : {"0", "-1", "abc", "5x", "", "1025", "99999999999"}) {
    threads.Set(bad);
    try {
      ThreadCount(0);
      ADD_FAILURE() << "accepted SLAMRIG_THREADS=" << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("SLAMRIG_THREADS=") + bad + ":"),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace slamrig::slam
