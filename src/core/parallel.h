// A small fixed thread pool for data-parallel loops.
//
// ParallelFor(n, fn) runs fn(i) for i in [0, n) on the pool's threads plus
// the caller, and returns when all are done. Work is handed out by an atomic
// counter; results must not depend on which thread ran which index (the
// deriver writes each chunk to a position fixed in advance).
//
// Fork and join cost about a microsecond, not the tens of a mutex and a
// condition variable: solvers call ParallelFor hundreds of times a frame
// (cloth: a colour of constraints per call, 20 substeps). Indices are
// claimed with a compare-and-swap on one word holding the call's generation
// and the next index, so a worker that wakes late can never claim an index
// of a later call; idle workers spin for a short while (kSpin) before they
// sleep on a condition variable.
//
// One pool serves a whole process (SharedPool below): derivation,
// tessellation, particles and cloth all take a ThreadPool*, so a scene that
// runs them together does not start a pool each and oversubscribe the
// cores. A ParallelFor issued while the pool is already running one (from
// another thread, or nested inside a task) runs on its caller alone: the
// same results, since no result depends on which thread ran which index.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace sylva {

// A non-owning reference to a callable taking an index (C++26's
// std::function_ref, reduced to what the pool needs): two words, made
// without allocating, valid while the callable it refers to lives. The pool
// calls it only during ParallelFor, so a lambda passed to ParallelFor
// outlives every call.
class IndexFn {
 public:
  template <typename Fn, typename = std::enable_if_t<!std::is_same_v<std::decay_t<Fn>, IndexFn>>>
  IndexFn(Fn&& fn)  // NOLINT: implicit, as std::function's
      : object_(const_cast<void*>(static_cast<const void*>(std::addressof(fn)))),
        call_([](void* o, size_t i) { (*static_cast<std::remove_reference_t<Fn>*>(o))(i); }) {}
  void operator()(size_t i) const { call_(object_, i); }

 private:
  void* object_;
  void (*call_)(void*, size_t);
};

class ThreadPool {
 public:
  // threads = total workers including the caller; 0 = hardware concurrency.
  explicit ThreadPool(int threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int threads() const { return threads_; }
  // Allocates nothing (fn is referred to, not copied).
  void ParallelFor(size_t n, IndexFn fn);
  // fn(part) for every part < parts, in parallel, each part on the thread
  // whose CurrentWorker() is part % threads() where that thread is there
  // to take it (else on another): data a part writes in one call and
  // reads in the next stays in one core's cache, where ParallelFor's
  // claims would hand it to either thread (an iterative solver's passes
  // then move their arrays between the cores every pass). parts at most
  // threads(); more run as ParallelFor.
  void ForEachPart(size_t parts, IndexFn fn);
  // The calling thread's place in the pool it works for: 1 to threads() -
  // 1 on a worker, 0 on any other thread (a ParallelFor's caller).
  static int CurrentWorker();

  static int HardwareThreads();

 private:
  void RunSerially(size_t n, IndexFn fn) {
    for (size_t i = 0; i < n; ++i) fn(i);
  }
  std::atomic<bool> busy_{false};  // a ParallelFor is running
  void WorkerLoop(int index);
  // Runs indices of generation `gen` until none is left or the pool has
  // moved on to a later call.
  void RunTasks(uint32_t gen);

  // Workers start on the first call with work for more than one thread, so
  // a pool that only ever sees small jobs (a short derivation) costs no
  // thread creation.
  int threads_ = 1;
  std::vector<std::thread> workers_;
  // The claim word: generation in the high 32 bits, next index in the low.
  alignas(64) std::atomic<uint64_t> claim_{0};
  alignas(64) std::atomic<size_t> finished_{0};
  // Published by the store to claim_ (atomic only so that a late reader
  // racing the next call is defined; its claim then fails).
  std::atomic<const IndexFn*> fn_{nullptr};
  std::atomic<size_t> count_{0};
  uint32_t generation_ = 0;  // the caller's copy
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<int> sleepers_{0};
  std::atomic<bool> stop_{false};
};

// The process's pool, made on first use with `threads` workers (0: every
// hardware thread); later calls return the same pool whatever they ask.
ThreadPool& SharedPool(int threads = 0);

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

// A grain that gives every thread of the pool about four ranges of at least
// minGrain and at most maxGrain items: a loop of a few thousand items still
// splits evenly over the threads.
inline size_t BalancedGrain(const ThreadPool* pool, size_t n, size_t minGrain,
                            size_t maxGrain = SIZE_MAX) {
  if (!pool) return std::max<size_t>(n, 1);
  const size_t even = (n + 4 * size_t(pool->threads()) - 1) / (4 * size_t(pool->threads()));
  return std::clamp(even, minGrain, std::max(minGrain, maxGrain));
}

}  // namespace sylva
