// What System (system.h) and BulkSystem (bulk.h) share, written once: the
// choice of thread pool, masses and the pinned flag, the fault latch and its
// scan, removing the dead, the state's fingerprint and its kinetic energy.
// Internal to the particle library: each system wraps these in its own
// public members, over its own storage (double or single precision).
#pragma once

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <type_traits>
#include <vector>

#include "core/math.h"
#include "core/parallel.h"
#include "core/status.h"

namespace sylva::particles {

// The largest mass a particle may have, kg.
constexpr double kMaxMass = 1e30;

// The thread pool a particle system runs on: its own (SetThreads) or one
// shared with the process (UsePool); null pool() means serial.
class PoolChoice {
 public:
  // 0 = every hardware thread; 1 = serial.
  void SetThreads(int threads);
  // `pool` is not owned and must outlive the system; null: serial.
  void UsePool(ThreadPool* pool);
  int threads() const { return threads_; }
  ThreadPool* pool() const { return pool_; }

 private:
  std::unique_ptr<ThreadPool> own_;
  ThreadPool* pool_ = nullptr;
  int threads_ = 1;
};

// Masses. A particle's mass is in (0, kMaxMass] kg; an immovable particle
// is pinned explicitly (inverse mass 0, its mass kept), never by a mass of
// 0. A state remembers the first particle added with a mass outside that
// range (the Add functions return ids, not statuses), and the next step
// reports it.
struct MassRecord {
  bool bad = false;
  uint32_t id = 0;  // the first particle added with a bad mass
  double mass = 0;  // and that mass
};
inline bool ValidMass(double m) {
  return m > 0 && m <= kMaxMass;
}
// The inverse mass of a particle added with mass m: 1/m, or NaN for a bad
// mass, which `record` keeps: the next step refuses to run (CheckMasses),
// and a NaN could never pass for a pinned particle's 0.
double InverseMassOf(double m, uint32_t id, MassRecord* record);
// The step's check, O(1) unless a bad mass was added: an error naming the
// first particle whose mass is bad and that is not pinned; clears the
// record when none is left (pinned, given a mass in range, or removed).
template <typename MassAt, typename PinnedAt, typename IdAt>
Status CheckMasses(const char* what, MassRecord* record, size_t n, MassAt massAt, PinnedAt pinnedAt,
                   IdAt idAt);

// The faults of a step (see system.h, "Faults"). The per-particle loops
// Flag() a particle that may be out of bounds and report unresolved
// contacts; Scan, after the step, names the first faulty particle. A fault
// latches: the system refuses to step again.
class FaultLatch {
 public:
  // At the start of a step: maxMagnitude, checked already.
  void Begin(double maxMagnitude);
  // maxMagnitude squared (at most DBL_MAX), for MaybeWithinLimit.
  double limit2() const { return limit2_; }
  void Flag() { flagged_.store(true, std::memory_order_relaxed); }
  // Particle i's contacts are unresolved; the lowest index wins, whatever
  // the thread count.
  void Unresolved(size_t i);
  // Particle i's radius is negative, not finite or beyond the limit (see
  // BadRadiusIn); the lowest index wins, whatever the thread count.
  void BadRadius(size_t i);
  const std::optional<Diagnostic>& fault() const { return fault_; }
  // Latches d and returns it.
  Diagnostic Latch(Diagnostic d) {
    fault_ = d;
    return d;
  }
  // After the step: ok, or the latched fault of the particle with the
  // lowest index whose radius was bad, else of the one with the lowest
  // index whose contacts were unresolved, else of the first whose
  // position or velocity has a component that is not finite or beyond
  // `limit` (each of the six compared on its own). at(i) gives particle i's
  // id, position, velocity and radius.
  struct Particle {
    uint32_t id;
    Vec3 x, v;
    double radius;
  };
  template <typename At>
  Status Scan(const char* what, uint64_t step, double t, size_t n, double limit, At at);

 private:
  std::optional<Diagnostic> fault_;
  std::atomic<bool> flagged_{false};
  std::atomic<size_t> unresolved_{SIZE_MAX};
  std::atomic<size_t> badRadius_{SIZE_MAX};
  double limit2_ = 0;
};

// The index of the first radius in [b, e) that is negative, not finite or
// whose square exceeds limit2 (the fault limit squared), else SIZE_MAX.
// Every collider and particle collisions take a particle's radius as
// given, so one of these would make them silently wrong (a negative radius
// lets a ball sink through a mesh, a NaN one moves it anywhere). One
// vectorised pass, then a scalar one only where a bad radius is.
size_t BadRadiusIn(const float* r, size_t b, size_t e, double limit2);

// Removes the particles for which dead(i) holds from every array, keeping
// the order of the living; remap (when not null) gets, for each old index,
// the new one or kRemoved. Returns the number removed. Allocates nothing
// unless remap needs to grow.
constexpr uint32_t kRemoved = UINT32_MAX;
template <typename Dead, typename... Arrays>
size_t RemoveIf(size_t n, Dead dead, std::vector<uint32_t>* remap, Arrays&... arrays);

// FNV-1a over bit patterns, with a fold: the fingerprint both systems give
// of their positions and velocities.
class BitHash {
 public:
  template <typename T>
  void Mix(T value) {
    static_assert(sizeof(T) == 8 || sizeof(T) == 4);
    std::conditional_t<sizeof(T) == 8, uint64_t, uint32_t> bits;
    std::memcpy(&bits, &value, sizeof bits);
    h_ = (h_ ^ bits) * 1099511628211ULL;
    h_ ^= h_ >> 29;
  }
  uint64_t value() const { return h_; }

 private:
  uint64_t h_ = 1469598103934665603ULL;
};

// Sum of |v|^2 / (2 w) over particles of inverse mass w > 0 (the pinned and
// the stuck do not count); at(i) gives w and v.
template <typename At>
double KineticEnergyOf(size_t n, At at) {
  double e = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto [w, v] = at(i);
    if (w > 0) e += 0.5 * v.squaredNorm() / w;
  }
  return e;
}

// Diagnostics shared by both systems (system.cpp).
Diagnostic ExplosionDiagnostic(const char* what, uint64_t step, double t, uint32_t id,
                               const Vec3& x, const Vec3& v, double limit);
Diagnostic BadRadiusDiagnostic(const char* what, uint64_t step, double t, uint32_t id,
                               double radius, double limit);
Diagnostic UnresolvedContactDiagnostic(const char* what, uint64_t step, double t, uint32_t id,
                                       const Vec3& x);
Diagnostic BadMassDiagnostic(const char* what, uint32_t id, double mass);

// Whether every component of x and v lies in [-limit, limit]. NaN fails:
// each of the six is compared on its own, never through a maximum (which
// drops a NaN in y or z).
inline bool WithinLimit(const Vec3& x, const Vec3& v, double limit) {
  bool ok = true;
  for (int k = 0; k < 3; ++k) ok &= std::abs(x[k]) <= limit && std::abs(v[k]) <= limit;
  return ok;
}

// A cheap screen for WithinLimit in the per-particle loops: false whenever
// WithinLimit is (a NaN or infinity makes the sum NaN or infinite, a
// component beyond the limit makes it exceed limit2), and rarely otherwise;
// the fault scan then applies WithinLimit itself. limit2 is the limit
// squared, at most DBL_MAX.
inline bool MaybeWithinLimit(const Vec3& x, const Vec3& v, double limit2) {
  return x.squaredNorm() + v.squaredNorm() <= limit2;
}

// --- templates ---

template <typename MassAt, typename PinnedAt, typename IdAt>
Status CheckMasses(const char* what, MassRecord* record, size_t n, MassAt massAt, PinnedAt pinnedAt,
                   IdAt idAt) {
  if (!record->bad) return {};
  for (size_t i = 0; i < n; ++i) {
    const double m = massAt(i);
    if (ValidMass(m) || pinnedAt(i)) continue;
    const uint32_t id = idAt(i);
    return BadMassDiagnostic(what, id, id == record->id ? record->mass : m);
  }
  *record = {};  // pinned, given a mass or removed since
  return {};
}

template <typename At>
Status FaultLatch::Scan(const char* what, uint64_t step, double t, size_t n, double limit, At at) {
  if (!flagged_.load()) return {};
  if (const size_t i = badRadius_.exchange(SIZE_MAX); i != SIZE_MAX) {
    unresolved_ = SIZE_MAX;
    const Particle p = at(i);
    return Latch(BadRadiusDiagnostic(what, step, t, p.id, p.radius, limit));
  }
  if (const size_t i = unresolved_.exchange(SIZE_MAX); i != SIZE_MAX) {
    const Particle p = at(i);
    return Latch(UnresolvedContactDiagnostic(what, step, t, p.id, p.x));
  }
  for (size_t i = 0; i < n; ++i) {
    const Particle p = at(i);
    if (WithinLimit(p.x, p.v, limit)) continue;
    return Latch(ExplosionDiagnostic(what, step, t, p.id, p.x, p.v, limit));
  }
  flagged_ = false;
  return {};
}

template <typename Dead, typename... Arrays>
size_t RemoveIf(size_t n, Dead dead, std::vector<uint32_t>* remap, Arrays&... arrays) {
  if (remap) remap->resize(n);
  size_t w = 0;
  for (size_t i = 0; i < n; ++i) {
    if (dead(i)) {
      if (remap) (*remap)[i] = kRemoved;
      continue;
    }
    if (w != i) ((arrays[w] = arrays[i]), ...);
    if (remap) (*remap)[i] = uint32_t(w);
    ++w;
  }
  (arrays.resize(w), ...);
  return n - w;
}

}  // namespace sylva::particles
