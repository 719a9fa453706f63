#include "particles/particle_core.h"

#include <cfloat>
#include <cmath>
#include <sstream>
#include <string>

#include "particles/collider.h"

namespace sylva::particles {
namespace {

std::string Format(const Vec3& v) {
  std::ostringstream o;
  o.precision(6);
  o << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return o.str();
}

}  // namespace

void PoolChoice::SetThreads(int threads) {
  threads_ = threads <= 0 ? ThreadPool::HardwareThreads() : threads;
  own_ = threads_ > 1 ? std::make_unique<ThreadPool>(threads_) : nullptr;
  pool_ = own_.get();
}

void PoolChoice::UsePool(ThreadPool* pool) {
  own_.reset();
  pool_ = pool && pool->threads() > 1 ? pool : nullptr;
  threads_ = pool ? pool->threads() : 1;
}

double InverseMassOf(double m, uint32_t id, MassRecord* record) {
  if (ValidMass(m)) return 1 / m;
  if (!record->bad) *record = {true, id, m};
  return std::nan("");
}

void FaultLatch::Begin(double maxMagnitude) {
  flagged_ = false;
  // A step that returned before its scan (a non-positive-definite
  // implicit system) leaves nothing behind for the next one.
  unresolved_ = SIZE_MAX;
  badRadius_ = SIZE_MAX;
  limit2_ = std::min(maxMagnitude * maxMagnitude, DBL_MAX);
}

void FaultLatch::Unresolved(size_t i) {
  size_t seen = unresolved_.load(std::memory_order_relaxed);
  while (i < seen && !unresolved_.compare_exchange_weak(seen, i)) {
  }
  Flag();
}

size_t BadRadiusIn(const float* r, size_t b, size_t e, double limit2) {
  // lim rounded toward zero; the vector pass (an int mask, which the
  // compiler vectorises) passes a chunk whose every radius is in [0, lim].
  const double limit = std::min(std::sqrt(limit2), double(FLT_MAX));
  float lim = float(limit);
  if (double(lim) > limit) lim = std::nextafter(lim, 0.0f);
  int ok = -1;
  for (size_t i = b; i < e; ++i) ok &= -int((r[i] >= 0.0f) & (r[i] <= lim));
  if (ok) return SIZE_MAX;
  for (size_t i = b; i < e; ++i) {
    if (!(r[i] >= 0.0f && double(r[i]) * double(r[i]) <= limit2)) return i;
  }
  return SIZE_MAX;  // only rounding of lim: within the limit
}

void FaultLatch::BadRadius(size_t i) {
  size_t seen = badRadius_.load(std::memory_order_relaxed);
  while (i < seen && !badRadius_.compare_exchange_weak(seen, i)) {
  }
  Flag();
}

Diagnostic BadMassDiagnostic(const char* what, uint32_t id, double mass) {
  std::ostringstream o;
  o << "particles: " << what << ": particle id " << id << " has mass " << mass
    << " kg, outside (0, " << kMaxMass
    << "] kg; a mass of 0 does not pin a particle: pin it explicitly (ParticleState::AddPinned "
       "or Pin, BulkState::AddPinned or Pin); nothing moved";
  return MakeError({}, o.str());
}

Diagnostic ExplosionDiagnostic(const char* what, uint64_t step, double t, uint32_t id,
                               const Vec3& x, const Vec3& v, double limit) {
  const bool finite = x.allFinite() && v.allFinite();
  std::ostringstream o;
  o << "particles: " << what << " step " << step << " (from t = " << t << " s): particle id " << id
    << " has position " << Format(x) << " and velocity " << Format(v)
    << (finite ? " beyond the limit of " : " (not finite)");
  if (finite) o << limit;
  o << "; the state exploded: try a smaller step, a stabler integrator or softer forces";
  Diagnostic d = MakeError({}, o.str());
  d.kind = ErrorKind::kRuntime;
  return d;
}

Diagnostic BadRadiusDiagnostic(const char* what, uint64_t step, double t, uint32_t id,
                               double radius, double limit) {
  std::ostringstream o;
  o << "particles: " << what << " step " << step << " (from t = " << t << " s): particle id " << id
    << " has radius " << radius << " m, outside [0, " << limit
    << "] m (maxMagnitude); the colliders and particle collisions met it with that radius, so "
       "this step's contacts for it are not right";
  Diagnostic d = MakeError({}, o.str());
  d.kind = ErrorKind::kRuntime;
  return d;
}

Diagnostic UnresolvedContactDiagnostic(const char* what, uint64_t step, double t, uint32_t id,
                                       const Vec3& x) {
  std::ostringstream o;
  o << "particles: " << what << " step " << step << " (from t = " << t << " s): particle id " << id
    << " still met a collider after " << kMaxContacts
    << " contacts in one step (a crevice narrower than the step resolves); it was stopped at its "
       "last contact point "
    << Format(x) << "; try a smaller step";
  Diagnostic d = MakeError({}, o.str());
  d.kind = ErrorKind::kRuntime;
  return d;
}

}  // namespace sylva::particles
