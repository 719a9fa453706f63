#include "core/parallel.h"

#include <algorithm>
#include <chrono>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SYLVA_PAUSE() _mm_pause()
#else
#define SYLVA_PAUSE() ((void)0)
#endif

namespace sylva {
namespace {

// How long an idle worker spins before it sleeps, and how long the caller
// spins on the join before it yields its core.
constexpr auto kSpin = std::chrono::microseconds(50);

// A pool worker's place in its pool (ThreadPool::CurrentWorker).
thread_local int tWorker = 0;

constexpr uint32_t Gen(uint64_t word) {
  return uint32_t(word >> 32);
}
constexpr uint32_t Index(uint64_t word) {
  return uint32_t(word);
}

}  // namespace

int ThreadPool::HardwareThreads() {
  unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : int(n);
}

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = HardwareThreads();
  threads_ = std::min(threads, 256);
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_.store(true);
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::RunTasks(uint32_t gen) {
  uint64_t word = claim_.load(std::memory_order_acquire);
  for (;;) {
    if (Gen(word) != gen) return;
    // fn_ and count_ were written before the word that published `gen` and
    // after the word that closed the call before; a value of a later call
    // makes the claim below fail, since its word was closed first.
    const size_t count = count_.load(std::memory_order_acquire);
    const IndexFn* fn = fn_.load(std::memory_order_acquire);
    if (Index(word) >= count) return;
    if (!claim_.compare_exchange_weak(word, word + 1, std::memory_order_acq_rel,
                                      std::memory_order_acquire)) {
      continue;  // word now holds the current value
    }
    (*fn)(Index(word));
    finished_.fetch_add(1, std::memory_order_acq_rel);
    word = claim_.load(std::memory_order_acquire);
  }
}

int ThreadPool::CurrentWorker() {
  return tWorker;
}

void ThreadPool::WorkerLoop(int index) {
  tWorker = index;
  uint32_t seen = 0;
  for (;;) {
    // Spin a little for the next call, then sleep.
    const auto until = std::chrono::steady_clock::now() + kSpin;
    uint32_t gen = Gen(claim_.load(std::memory_order_acquire));
    for (int spins = 0; gen == seen && !stop_.load(std::memory_order_relaxed); ++spins) {
      SYLVA_PAUSE();
      if ((spins & 63) == 63 && std::chrono::steady_clock::now() > until) {
        std::unique_lock<std::mutex> lock(mutex_);
        sleepers_.fetch_add(1);
        wake_.wait(lock, [&] { return stop_.load() || Gen(claim_.load()) != seen; });
        sleepers_.fetch_sub(1);
      }
      gen = Gen(claim_.load(std::memory_order_acquire));
    }
    if (stop_.load()) return;
    seen = gen;
    RunTasks(gen);
  }
}

ThreadPool& SharedPool(int threads) {
  static ThreadPool pool(threads);
  return pool;
}

void ThreadPool::ParallelFor(size_t n, IndexFn fn) {
  if (n == 0) return;
  if (threads_ == 1 || n == 1) {
    RunSerially(n, fn);
    return;
  }
  if (n >= std::numeric_limits<uint32_t>::max()) {  // the claim word holds 32-bit indices
    const size_t half = n / 2;
    ParallelFor(half, fn);
    auto rest = [&](size_t i) { fn(half + i); };
    ParallelFor(n - half, rest);
    return;
  }
  // One call at a time: a second caller (another thread, or a task of this
  // call) runs its loop itself instead of waiting or corrupting this one.
  bool expected = false;
  if (!busy_.compare_exchange_strong(expected, true, std::memory_order_acquire)) {
    RunSerially(n, fn);
    return;
  }
  struct Release {
    std::atomic<bool>& busy;
    ~Release() { busy.store(false, std::memory_order_release); }
  } release{busy_};
  if (workers_.empty()) {
    for (int i = 1; i < threads_; ++i) workers_.emplace_back([this, i] { WorkerLoop(i); });
  }
  fn_.store(&fn, std::memory_order_release);
  count_.store(n, std::memory_order_release);
  finished_.store(0, std::memory_order_relaxed);
  ++generation_;
  claim_.store(uint64_t(generation_) << 32);  // seq_cst: ordered against sleepers_
  if (sleepers_.load() > 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    wake_.notify_all();
  }
  RunTasks(generation_);
  // Join: every index claimed has finished (no worker holds fn after that).
  const auto until = std::chrono::steady_clock::now() + kSpin;
  for (int spins = 0; finished_.load(std::memory_order_acquire) != n; ++spins) {
    SYLVA_PAUSE();
    if ((spins & 63) == 63 && std::chrono::steady_clock::now() > until) std::this_thread::yield();
  }
  // Close the call: no claim on this generation can succeed any more, even
  // by a worker that read the next call's count.
  claim_.store(uint64_t(generation_) << 32 | 0xffffffffu);
  fn_.store(nullptr, std::memory_order_release);
}

void ThreadPool::ForEachPart(size_t parts, IndexFn fn) {
  if (parts > size_t(threads_)) return ParallelFor(parts, fn);
  // Each index claimed takes one part, its thread's own if it is free:
  // parts indices take every part once.
  std::atomic<bool> taken[256];
  for (size_t i = 0; i < parts; ++i) taken[i].store(false, std::memory_order_relaxed);
  auto take = [&](size_t) {
    const size_t own = size_t(tWorker) % parts;
    for (size_t k = 0; k < parts; ++k) {
      const size_t part = (own + k) % parts;
      if (!taken[part].exchange(true, std::memory_order_acq_rel)) {
        fn(part);
        return;
      }
    }
  };
  ParallelFor(parts, take);
}

}  // namespace sylva
