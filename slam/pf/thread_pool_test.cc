#include "slam/pf/thread_pool.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <string>

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
