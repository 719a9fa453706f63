#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
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

// ForEachPart runs every part once a call; on a pool of two threads with
// two parts, where both threads ran a part in a call, each ran its own
// (the worker part 1, the caller, whose place is 0, part 0). Either thread
// may run both (a caller descheduled after it published the call leaves
// both indices to the worker, which then takes part 0 too: that is how
// the pool keeps going, and it happened under load). (With three, a fast
// caller may take a worker's part and leave it another.)
TEST(ThreadPool, ForEachPartRunsEveryPartOnceAndAWorkerItsOwn) {
  EXPECT_EQ(ThreadPool::CurrentWorker(), 0);
  for (int threads : {1, 2, 3}) {
    ThreadPool pool(threads);
    for (size_t parts : {size_t(1), size_t(threads), size_t(threads + 2)}) {
      std::vector<std::atomic<int>> hits(parts);
      int shared = 0, foreign = 0;  // calls both threads ran parts in; of them, swapped
      for (int round = 0; round < 500; ++round) {
        std::vector<std::atomic<int>> by(parts);  // the place of the thread that ran each
        pool.ForEachPart(parts, [&](size_t part) {
          hits[part].fetch_add(1);
          by[part].store(ThreadPool::CurrentWorker());
        });
        if (threads == 2 && parts == 2 && by[0].load() != by[1].load()) {
          ++shared;
          foreign += by[0].load() != 0 || by[1].load() != 1;
        }
      }
      for (size_t i = 0; i < parts; ++i)
        ASSERT_EQ(hits[i].load(), 500)
            << "part " << i << " of " << parts << ", threads " << threads;
      EXPECT_EQ(foreign, 0) << "calls where the two threads ran each other's part, of " << shared
                            << " where both ran one; threads " << threads;
    }
  }
}

// Many short calls back to back (workers still spinning from the last one)
// and calls after a pause (workers asleep): every index runs exactly once.
TEST(ThreadPool, BackToBackAndAfterSleepCallsRunEveryIndexOnce) {
  ThreadPool pool(3);
  std::vector<std::atomic<int>> hits(64);
  for (int round = 0; round < 20000; ++round) {
    const size_t n = 1 + size_t(round % 64);
    pool.ParallelFor(n, [&](size_t i) { hits[i].fetch_add(1, std::memory_order_relaxed); });
  }
  for (int round = 0; round < 5; ++round) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    pool.ParallelFor(64, [&](size_t i) { hits[i].fetch_add(1, std::memory_order_relaxed); });
  }
  // Index i ran in every round with n > i: rounds r with (r % 64) >= i.
  for (size_t i = 0; i < hits.size(); ++i) {
    int want = 5;
    for (int round = 0; round < 20000; ++round) want += (round % 64) >= int(i) ? 1 : 0;
    ASSERT_EQ(hits[i].load(), want) << "index " << i;
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

namespace sylva {

TEST(PodBuffer, LargeBuffersGrowInPlaceAndKeepContents) {
  PodBuffer<uint32_t> b;
  b.ResizeUninitialized(3 << 20);  // 12 MiB: mapped
  for (uint32_t i = 0; i < b.size(); ++i) b[i] = i * 7;
  b.ResizeUninitialized(10 << 20);  // grows with mremap
  for (uint32_t i = 0; i < (3u << 20); i += 4099) ASSERT_EQ(b[i], i * 7) << i;
  PodBuffer<uint32_t> c = b;  // copy of a mapped buffer
  b.ResizeUninitialized(5);
  b.shrink_to_fit();  // back to malloc
  EXPECT_EQ(b[4], 28u);
  EXPECT_EQ(c[(3u << 20) - 1], ((3u << 20) - 1) * 7);
  PodBuffer<uint32_t> d(std::move(c));
  EXPECT_EQ(d[12345], 12345u * 7);
}

}  // namespace sylva

namespace sylva {
namespace {

// One pool serves the whole process: a second caller on another thread, or
// a task that calls ParallelFor again, runs its loop itself, and every
// index of every call runs exactly once.
TEST(ThreadPool, ConcurrentAndNestedCallersEachRunEveryIndexOnce) {
  ThreadPool pool(4);
  constexpr size_t kN = 20000;
  std::vector<std::atomic<int>> a(kN), b(kN), nested(64 * 64);
  std::thread other([&] {
    for (int round = 0; round < 50; ++round)
      pool.ParallelFor(kN, [&](size_t i) { b[i].fetch_add(1, std::memory_order_relaxed); });
  });
  for (int round = 0; round < 50; ++round)
    pool.ParallelFor(kN, [&](size_t i) { a[i].fetch_add(1, std::memory_order_relaxed); });
  other.join();
  pool.ParallelFor(64, [&](size_t i) {
    pool.ParallelFor(64, [&](size_t j) { nested[i * 64 + j].fetch_add(1); });
  });
  for (size_t i = 0; i < kN; ++i) {
    ASSERT_EQ(a[i].load(), 50) << "index " << i << " of the first caller";
    ASSERT_EQ(b[i].load(), 50) << "index " << i << " of the second caller";
  }
  for (size_t i = 0; i < nested.size(); ++i) ASSERT_EQ(nested[i].load(), 1) << "nested " << i;
  EXPECT_EQ(&SharedPool(3), &SharedPool(1)) << "one shared pool a process";
}

}  // namespace
}  // namespace sylva
