// PodBuffer<T>: a growable array of trivially copyable T that does not
// zero-fill on resize.
//
// Words of 100+ million modules are sized exactly before they are written,
// so value-initialising them (as std::vector does) would cost a full extra
// pass over memory. On Linux, buffers of 4 MiB or more are mapped directly:
// they ask for transparent huge pages (a 250 MB word takes ~120 page faults
// instead of 61,000) and grow with mremap, which keeps the pages already
// touched instead of copying them into fresh memory that the kernel must
// zero first. The deriver's buffers are reused from step to step, so each
// step faults in only the part of its output beyond what earlier steps used.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "core/assert.h"

namespace sylva {

template <typename T>
class PodBuffer {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  PodBuffer() = default;
  explicit PodBuffer(size_t n) { ResizeUninitialized(n); }
  ~PodBuffer() { Release(); }
  PodBuffer(const PodBuffer& o) { *this = o; }
  PodBuffer& operator=(const PodBuffer& o) {
    if (this != &o) {
      size_ = 0;
      ResizeUninitialized(o.size_);
      if (o.size_) std::memcpy(data_, o.data_, o.size_ * sizeof(T));
    }
    return *this;
  }
  PodBuffer(PodBuffer&& o) noexcept { swap(o); }
  PodBuffer& operator=(PodBuffer&& o) noexcept {
    swap(o);
    return *this;
  }

  void swap(PodBuffer& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(capacity_, o.capacity_);
    std::swap(mapped_, o.mapped_);
  }

  // New elements are left uninitialised; old ones are kept.
  void ResizeUninitialized(size_t n) {
    if (n > capacity_) Reallocate(n);
    size_ = n;
  }
  void reserve(size_t n) {
    if (n > capacity_) Reallocate(n);
  }
  void clear() { size_ = 0; }
  void shrink_to_fit() {
    if (size_ < capacity_) Reallocate(size_);
  }
  void push_back(const T& v) {
    if (size_ == capacity_) Reallocate(capacity_ < 16 ? 16 : capacity_ * 2);
    data_[size_++] = v;
  }
  void append(const T* p, size_t n) {
    if (size_ + n > capacity_) Reallocate(std::max(size_ + n, capacity_ * 2));
    if (n) std::memcpy(data_ + size_, p, n * sizeof(T));
    size_ += n;
  }

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T& operator[](size_t i) {
    SYLVA_DCHECK(i < size_);
    return data_[i];
  }
  const T& operator[](size_t i) const {
    SYLVA_DCHECK(i < size_);
    return data_[i];
  }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  size_t MemoryBytes() const { return capacity_ * sizeof(T); }

 private:
  static constexpr size_t kHugePage = size_t(2) << 20;
  static constexpr size_t kMapThreshold = 2 * kHugePage;

  void Release() {
#if defined(__linux__)
    if (mapped_) {
      munmap(data_, mapped_);
    } else {
      std::free(data_);
    }
#else
    std::free(data_);
#endif
    data_ = nullptr;
    capacity_ = size_ = mapped_ = 0;
  }

  void Reallocate(size_t cap) {
    const size_t keep = std::min(size_, cap);
    const size_t bytes = cap * sizeof(T);
#if defined(__linux__)
    if (bytes >= kMapThreshold) {
      const size_t want = (bytes + kHugePage - 1) / kHugePage * kHugePage;
      void* p;
      if (mapped_) {
        p = mremap(data_, mapped_, want, MREMAP_MAYMOVE);
      } else {
        p = mmap(nullptr, want, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p != MAP_FAILED && keep) std::memcpy(p, data_, keep * sizeof(T));
        if (p != MAP_FAILED) std::free(data_);
      }
      if (p == MAP_FAILED) throw std::bad_alloc();
#if defined(MADV_HUGEPAGE)
      madvise(p, want, MADV_HUGEPAGE);
#endif
      data_ = static_cast<T*>(p);
      mapped_ = want;
      capacity_ = want / sizeof(T);
      size_ = keep;
      return;
    }
#endif
    T* p = bytes ? static_cast<T*>(std::malloc(bytes)) : nullptr;
    if (bytes && !p) throw std::bad_alloc();
    if (keep) std::memcpy(p, data_, keep * sizeof(T));
    const size_t oldSize = keep;
    Release();
    data_ = p;
    capacity_ = cap;
    size_ = oldSize;
  }

  T* data_ = nullptr;
  size_t size_ = 0;
  size_t capacity_ = 0;
  size_t mapped_ = 0;  // bytes mapped with mmap, or 0 when malloc'd
};

}  // namespace sylva
