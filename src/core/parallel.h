// A small fixed thread pool for data-parallel loops.
//
// ParallelFor(n, fn) runs fn(i) for i in [0, n) on the pool's threads plus
// the caller, and returns when all are done. Work is handed out by an atomic
// counter; results must not depend on which thread ran which index (the
// deriver writes each chunk to a position fixed in advance).
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace sylva {

class ThreadPool {
 public:
  // threads = total workers including the caller; 0 = hardware concurrency.
  explicit ThreadPool(int threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int threads() const { return int(workers_.size()) + 1; }
  void ParallelFor(size_t n, const std::function<void(size_t)>& fn);

  static int HardwareThreads();

 private:
  void WorkerLoop();
  void RunTasks();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(size_t)>* fn_ = nullptr;
  size_t count_ = 0;
  size_t next_ = 0;
  size_t finished_ = 0;
  uint64_t generation_ = 0;
  int active_ = 0;
  bool stop_ = false;
};

// Runs fn(begin, end) over [0, n) in ranges of `grain`, on the pool when
// there is one and more than one range, else on the caller.
template <typename Fn>
void ForRanges(ThreadPool* pool, size_t n, size_t grain, Fn&& fn) {
  const size_t ranges = (n + grain - 1) / grain;
  if (!pool || ranges <= 1) {
    if (n) fn(size_t(0), n);
    return;
  }
  pool->ParallelFor(ranges, [&](size_t r) { fn(r * grain, std::min(n, (r + 1) * grain)); });
}

}  // namespace sylva
