#include "slam/pf/thread_pool.h"

#include <gtest/gtest.h>

#include <atomic>

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

}  // namespace
}  // namespace slamrig::slam
