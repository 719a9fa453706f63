// Allocations during a step: none, once the state and scratch exist. This
// program replaces the global operator new with a counting one (which is
// why it is a program of its own), and counts across Step calls on every
// thread of the system's pool.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "helpers.h"
#include "particles/bulk.h"
#include "particles/forces.h"
#include "particles/system.h"

namespace {
std::atomic<uint64_t> gAllocations{0};
}  // namespace

void* operator new(size_t n) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n) {
  return operator new(n);
}
void* operator new(size_t n, std::align_val_t a) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  const size_t align = size_t(a);
  if (void* p = std::aligned_alloc(align, (n + align - 1) / align * align)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n, std::align_val_t a) {
  return operator new(n, a);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace sylva::particles {
namespace {

// Allocations made by fn.
template <typename Fn>
uint64_t Allocations(Fn&& fn) {
  const uint64_t before = gAllocations.load();
  fn();
  return gAllocations.load() - before;
}

// A system of n particles with gravity, drag, springs along a chain and a
// plane, on `threads` threads.
void Fill(System& s, int n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < n; ++i) s.state.Add(Vec3(u(rng), 1 + u(rng), u(rng)), Vec3::Zero());
  s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  s.AddForce(std::make_shared<Drag>(0.1, 0.01));
  auto springs = std::make_shared<Springs>();
  for (int i = 0; i + 1 < n; ++i)
    EXPECT_OK(springs->Add(uint32_t(i), uint32_t(i + 1), 0.01, 10, 0.1));
  s.AddForce(springs);
  EXPECT_OK(s.AddPlane(Plane{Vec3(0, -1, 0), Vec3(0, 1, 0), 0.5, 0.2}));
}

TEST(ParticleAllocations, SystemStepAllocatesNothing) {
  for (int threads : {1, 2}) {
    for (Integrator in :
         {Integrator::kSymplecticEuler, Integrator::kRK4, Integrator::kImplicitEuler}) {
      System s(threads);
      Fill(s, 20000);
      STEP_OK(s, 1e-3, in);  // the first step sizes the scratch and starts the pool
      STEP_OK(s, 1e-3, in);
      Status st;
      const uint64_t n = Allocations([&] {
        for (int k = 0; k < 10; ++k) st = s.Step(1e-3, in);
      });
      ASSERT_TRUE(st.ok()) << st.error().message;
      EXPECT_EQ(n, 0u) << "allocations in 10 steps on " << threads << " threads, integrator "
                       << int(in);
    }
  }
}

TEST(ParticleAllocations, BulkStepAllocatesNothing) {
  for (int threads : {1, 2}) {
    BulkSystem b(threads);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < 100000; ++i) b.state.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(0, -1, 0));
    b.fields.gravity = Vec3(0, -9.81, 0);
    b.fields.linearDrag = 0.1;
    ASSERT_OK(b.AddCollider(Collider::Plane(Vec3(0, -1, 0), Vec3(0, 1, 0)).Restitution(0.5)));
    ASSERT_OK(b.Step(1.0 / 60));
    Status st;
    const uint64_t n = Allocations([&] {
      for (int k = 0; k < 10; ++k) st = b.Step(1.0 / 60);
    });
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_EQ(n, 0u) << "allocations in 10 bulk steps on " << threads << " threads";
  }
}

// Particle collisions (pairs.cpp): a pile of 1,000 balls resting in a box
// under gravity, every ball in contact. Each chunk's contact array keeps
// its capacity, so once the pile has settled (no chunk holds more contacts
// than it has held before) a step allocates nothing.
TEST(ParticleAllocations, ParticleCollisionsAllocateNothingAtRest) {
  for (int threads : {1, 2}) {
    System s(threads);
    s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
    ASSERT_OK(s.AddCollider(
        Collider::Box(Vec3(-0.5, 0, -0.5), Vec3(0.5, 10, 0.5), true).Restitution(0.3)));
    for (int y = 0; y < 10; ++y)
      for (int z = 0; z < 10; ++z)
        for (int x = 0; x < 10; ++x) {
          s.state.Add(Vec3(-0.45 + 0.1 * x, 0.05 + 0.1 * y, -0.45 + 0.1 * z), Vec3::Zero());
          s.state.radius.back() = 0.05f;
        }
    ASSERT_OK(s.EnableParticleCollisions(0.05, 0.3));
    for (int k = 0; k < 60; ++k) STEP_OK(s, 1.0 / 60, Integrator::kSymplecticEuler);
    Status st;
    const uint64_t n = Allocations([&] {
      for (int k = 0; k < 10; ++k) st = s.Step(1.0 / 60, Integrator::kSymplecticEuler);
    });
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_EQ(n, 0u) << "allocations in 10 steps of a resting pile on " << threads << " threads";
  }
}

// The counter sees allocations at all (the test above could not pass by
// counting nothing).
TEST(ParticleAllocations, CounterCounts) {
  const uint64_t n = Allocations([] {
    auto* v = new std::vector<int>(100);
    delete v;
  });
  EXPECT_EQ(n, 2u) << "a vector of 100 ints, made with new";
}

}  // namespace
}  // namespace sylva::particles
