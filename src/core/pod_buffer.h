// PodBuffer<T>: a growable array of trivially copyable T that does not
// zero-fill on resize. Words of 100+ million modules are sized exactly before
// they are written, so value-initialising them (as std::vector does) would
// cost a full extra pass over memory. Buffers of 4 MiB or more are 2 MiB
// aligned and ask Linux for transparent huge pages: a 250 MB word then takes
// about 120 page faults instead of 61,000.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
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
  PodBuffer(const PodBuffer& o) { *this = o; }
  PodBuffer& operator=(const PodBuffer& o) {
    if (this != &o) {
      ResizeUninitialized(o.size_);
      if (o.size_) std::memcpy(data_.get(), o.data_.get(), o.size_ * sizeof(T));
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
    if (n) std::memcpy(data_.get() + size_, p, n * sizeof(T));
    size_ += n;
  }

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  T& operator[](size_t i) {
    SYLVA_DCHECK(i < size_);
    return data_[i];
  }
  const T& operator[](size_t i) const {
    SYLVA_DCHECK(i < size_);
    return data_[i];
  }
  T* begin() { return data(); }
  T* end() { return data() + size_; }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size_; }
  size_t MemoryBytes() const { return capacity_ * sizeof(T); }

 private:
  struct Free {
    void operator()(T* p) const { std::free(p); }
  };
  static constexpr size_t kHuge = size_t(2) << 20;

  static T* Allocate(size_t cap) {
    if (cap == 0) return nullptr;
    const size_t bytes = cap * sizeof(T);
    void* p;
    if (bytes >= 2 * kHuge) {
      p = std::aligned_alloc(kHuge, (bytes + kHuge - 1) / kHuge * kHuge);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
      if (p) madvise(p, bytes, MADV_HUGEPAGE);
#endif
    } else {
      p = std::malloc(bytes);
    }
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }

  void Reallocate(size_t cap) {
    std::unique_ptr<T[], Free> fresh(Allocate(cap));  // uninitialised: no zeroing
    if (size_ && cap) std::memcpy(fresh.get(), data_.get(), std::min(size_, cap) * sizeof(T));
    data_ = std::move(fresh);
    capacity_ = cap;
    if (size_ > cap) size_ = cap;
  }

  std::unique_ptr<T[], Free> data_;
  size_t size_ = 0;
  size_t capacity_ = 0;
};

}  // namespace sylva
