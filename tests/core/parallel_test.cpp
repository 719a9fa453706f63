#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "core/pod_buffer.h"

namespace sylva {

TEST(ThreadPool, ParallelForRunsEveryIndexOnce) {
  for (int threads : {1, 2, 4}) {
    ThreadPool pool(threads);
    std::vector<std::atomic<int>> hits(1000);
    for (int round = 0; round < 20; ++round) {
      pool.ParallelFor(hits.size(), [&](size_t i) { hits[i].fetch_add(1); });
    }
    for (size_t i = 0; i < hits.size(); ++i) {
      ASSERT_EQ(hits[i].load(), 20) << "index " << i << " threads " << threads;
    }
  }
}

TEST(PodBuffer, GrowsAndKeepsContents) {
  PodBuffer<int> b;
  for (int i = 0; i < 1000; ++i) b.push_back(i);
  b.ResizeUninitialized(2000);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(b[i], i);
  PodBuffer<int> c = b;
  c.ResizeUninitialized(10);
  EXPECT_EQ(c.size(), 10u);
  EXPECT_EQ(c[9], 9);
  EXPECT_EQ(b.size(), 2000u);
}

}  // namespace sylva
