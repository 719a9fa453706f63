#include "particles/system.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "particles/def_check.h"
#include "particles/grid.h"
#include "particles/pairs.h"

namespace sylva::particles {
namespace {

// Particles per chunk: the chunk's forces (96 KiB) stay in L2.
constexpr size_t kChunk = 4096;

std::string Format(const Vec3& v) {
  std::ostringstream o;
  o.precision(6);
  o << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return o.str();
}

}  // namespace

uint32_t ParticleState::Add(const Vec3& p, const Vec3& v, double m, double life) {
  position.push_back(p);
  velocity.push_back(v);
  mass.push_back(m);
  invMass.push_back(InverseMassOf(m, nextId, &massRecord));
  age.push_back(0);
  lifetime.push_back(life);
  color.push_back(Vec3f(1, 1, 1));
  radius.push_back(0.0f);
  id.push_back(nextId);
  return nextId++;
}

uint32_t ParticleState::AddPinned(const Vec3& p, double m, double life) {
  const uint32_t added = Add(p, Vec3::Zero(), m, life);
  Pin(size() - 1);
  return added;
}

// --- forces ---

void Gravity::AccumulateRange(const ParticleState& s, const Vec3*, const Vec3*, Vec3* f,
                              size_t begin, size_t end) const {
  const double* m = s.mass.data();
  for (size_t i = begin; i < end; ++i) f[i - begin] += m[i] * g_;
}

void Drag::AccumulateRange(const ParticleState&, const Vec3*, const Vec3* v, Vec3* f, size_t begin,
                           size_t end) const {
  if (k2_ == 0) {
    for (size_t i = begin; i < end; ++i) f[i - begin] -= k1_ * v[i];
  } else {
    for (size_t i = begin; i < end; ++i) f[i - begin] -= (k1_ + k2_ * v[i].norm()) * v[i];
  }
}

void Drag::AddJacobianProduct(const ParticleState& s, const Vec3*, const Vec3* v, double, double cv,
                              const Vec3* p, Vec3* y) const {
  if (cv == 0) return;
  for (size_t i = 0; i < s.size(); ++i) {
    const double speed = v[i].norm();
    Vec3 j = -(k1_ + k2_ * speed) * p[i];
    if (k2_ != 0 && speed > 0) j -= k2_ * v[i] * (v[i].dot(p[i]) / speed);
    y[i] += cv * j;
  }
}

Status Gravity::Check(const ParticleState&) const {
  return check::Finite("Gravity g", g_, 1e12, "m/s^2");
}

Status Drag::Check(const ParticleState&) const {
  SYLVA_CHECK_OK(check::Range("Drag linear", k1_, 0, 1e12, "N s/m"));
  return check::Range("Drag quadratic", k2_, 0, 1e12, "N s^2/m^2");
}

Status Springs::Add(uint32_t a, uint32_t b, double rest, double ks, double kd) {
  using namespace check;
  if (a == b) return Error("Springs.Add joins particle " + std::to_string(a) + " to itself");
  SYLVA_CHECK_OK(Range("Springs.Add rest", rest, 0, 1e12, "m"));
  SYLVA_CHECK_OK(Range("Springs.Add ks", ks, 0, 1e12, "N/m"));
  SYLVA_CHECK_OK(Range("Springs.Add kd", kd, 0, 1e12, "N s/m"));
  springs_.push_back({a, b, rest, ks, kd});
  maxIndex_ = std::max({maxIndex_, a, b});
  return {};
}

void Springs::Clear() {
  springs_.clear();
  maxIndex_ = 0;
  linear_.clear();
  length_.clear();
  preparedX_ = nullptr;
  accumulateCached_ = false;
  colouredSprings_ = SIZE_MAX;  // colour again, even for as many springs
}

void Springs::Renumber(const std::vector<uint32_t>& newIndex) {
  size_t kept = 0;
  maxIndex_ = 0;
  for (const Spring& sp : springs_) {
    // An index past newIndex is left out of range, for Check to report.
    const uint32_t a = sp.a < newIndex.size() ? newIndex[sp.a] : sp.a;
    const uint32_t b = sp.b < newIndex.size() ? newIndex[sp.b] : sp.b;
    if (a == kRemoved || b == kRemoved) continue;
    springs_[kept++] = {a, b, sp.rest, sp.ks, sp.kd};
    maxIndex_ = std::max({maxIndex_, a, b});
  }
  springs_.resize(kept);
  linear_.clear();
  length_.clear();
  preparedX_ = nullptr;
  accumulateCached_ = false;
  colouredSprings_ = SIZE_MAX;  // colour again
}

Status Springs::Check(const ParticleState& s) const {
  if (springs_.empty() || maxIndex_ < s.size()) return {};
  return check::Error("Springs: a spring joins particle " + std::to_string(maxIndex_) +
                      ", but the system has " + std::to_string(s.size()) + " particles");
}

void Springs::Colour() const {
  if (colouredSprings_ == springs_.size()) return;
  size_t n = 0;
  for (const Spring& sp : springs_) n = std::max<size_t>(n, std::max(sp.a, sp.b) + size_t(1));
  std::vector<uint64_t> used(n, 0);
  std::vector<int8_t> colour(springs_.size());
  int colours = 0;
  for (size_t k = 0; k < springs_.size(); ++k) {
    const Spring& sp = springs_[k];
    const uint64_t free = ~(used[sp.a] | used[sp.b]);
    if (free == 0) {
      colour[k] = -1;  // the serial group
      continue;
    }
    const int c = std::countr_zero(free);
    colour[k] = int8_t(c);
    used[sp.a] |= 1ULL << c;
    used[sp.b] |= 1ULL << c;
    colours = std::max(colours, c + 1);
  }
  std::vector<size_t> count(size_t(colours) + 2, 0);
  for (int8_t c : colour) ++count[c < 0 ? size_t(colours) + 1 : size_t(c) + 1];
  serialGroup_ = count[size_t(colours) + 1] > 0;
  colourStart_.assign(size_t(colours) + (serialGroup_ ? 2 : 1), 0);
  for (size_t c = 1; c < colourStart_.size(); ++c) colourStart_[c] = colourStart_[c - 1] + count[c];
  std::vector<size_t> fill(colourStart_.begin(), colourStart_.end() - 1);
  order_.resize(springs_.size());
  for (size_t k = 0; k < springs_.size(); ++k) {
    order_[fill[colour[k] < 0 ? size_t(colours) : size_t(colour[k])]++] = uint32_t(k);
  }
  colouredSprings_ = springs_.size();
  particles_ = n;
}

template <typename Fn>
void Springs::ForColours(Fn&& fn) const {
  Colour();
  for (size_t c = 0; c + 1 < colourStart_.size(); ++c) {
    const size_t first = colourStart_[c], count = colourStart_[c + 1] - first;
    auto range = [&](size_t b, size_t e) {
      for (size_t j = first + b; j < first + e; ++j) fn(j, springs_[order_[j]]);
    };
    if (serialGroup_ && c + 2 == colourStart_.size()) {
      range(0, count);
    } else {
      ForRanges(pool_, count, BalancedGrain(pool_, count, 256, 4096), range);
    }
  }
}

void Springs::Accumulate(const ParticleState&, const Vec3* x, const Vec3* v, Vec3* f) const {
  if (std::exchange(accumulateCached_, false) && x == preparedX_ &&
      linear_.size() == springs_.size()) {
    // The length and direction PrepareJacobian computed at these positions
    // (the same operations, so the same bits).
    ForColours([&](size_t j, const Spring& sp) {
      const double len = length_[j];
      if (!(len > 1e-300)) return;
      const Linear& l = linear_[j];
      const Vec3 dir(l.u[0], l.u[1], l.u[2]);
      const double rate = (v[sp.a] - v[sp.b]).dot(dir);
      const Vec3 fa = -(sp.ks * (len - sp.rest) + sp.kd * rate) * dir;
      f[sp.a] += fa;
      f[sp.b] -= fa;
    });
    return;
  }
  ForColours([&](size_t, const Spring& sp) {
    const Vec3 d = x[sp.a] - x[sp.b];
    const double len = d.norm();
    if (!(len > 1e-300)) return;
    const Vec3 dir = d / len;
    const double rate = (v[sp.a] - v[sp.b]).dot(dir);
    const Vec3 fa = -(sp.ks * (len - sp.rest) + sp.kd * rate) * dir;
    f[sp.a] += fa;
    f[sp.b] -= fa;
  });
}

Springs::Linear Springs::Linearise(const Spring& sp, const Vec3* x, double* length) {
  const Vec3 d = x[sp.a] - x[sp.b];
  const double len = d.norm();
  *length = len;
  if (!(len > 1e-300)) return {{0, 0, 0, 0}, sp.a, sp.b, 0, 0, sp.kd};
  const double kt = sp.ks * std::max(0.0, 1 - sp.rest / len);
  const Vec3 u = d / len;
  return {{u.x(), u.y(), u.z(), 0}, sp.a, sp.b, kt, sp.ks - kt, sp.kd};
}

void Springs::PrepareJacobian(const ParticleState&, const Vec3* x, const Vec3*) {
  Colour();
  preparedX_ = x;
  accumulateCached_ = true;
  linear_.resize(springs_.size());
  length_.resize(springs_.size());
  ForColours([&](size_t j, const Spring& sp) { linear_[j] = Linearise(sp, x, &length_[j]); });
}

void Springs::AddJacobianProduct(const ParticleState&, const Vec3* x, const Vec3*, double cx,
                                 double cv, const Vec3* p, Vec3* y) const {
  if (!(x == preparedX_ && linear_.size() == springs_.size())) {
    ForColours([&](size_t, const Spring& sp) {
      double len;
      const Linear l = Linearise(sp, x, &len);
      kernels::SpringProduct(l, cx, cv, p[l.a].data(), p[l.b].data(), y[l.a].data(), y[l.b].data());
    });
    return;
  }
  // On padded copies of p and y (see kernels.h), colour by colour.
  const size_t n = particles_;
  p4_.resize(n);
  y4_.resize(n);
  const size_t grain = BalancedGrain(pool_, n, 512, 4096);
  ForRanges(pool_, n, grain, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      p4_[i] = {{p[i].x(), p[i].y(), p[i].z(), 0}};
      y4_[i] = {{y[i].x(), y[i].y(), y[i].z(), 0}};
    }
  });
  const Linear* lin = linear_.data();
  for (size_t c = 0; c + 1 < colourStart_.size(); ++c) {
    const size_t first = colourStart_[c], last = colourStart_[c + 1];
    if (serialGroup_ && c + 2 == colourStart_.size()) {
      kernels::SpringProductRange(kernels::Kernel::kScalar, lin, first, last, cx, cv, p4_.data(),
                                  y4_.data());
    } else {
      ForRanges(pool_, last - first, BalancedGrain(pool_, last - first, 256, 4096),
                [&](size_t b, size_t e) {
                  kernels::SpringProductRange(kernel_, lin, first + b, first + e, cx, cv,
                                              p4_.data(), y4_.data());
                });
    }
  }
  ForRanges(pool_, n, grain, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) y[i] = Vec3(y4_[i].p[0], y4_[i].p[1], y4_[i].p[2]);
  });
}

void Springs::AddJacobianDiagonal(const ParticleState&, const Vec3* x, const Vec3*, double cx,
                                  double cv, Vec3* diag) const {
  const bool cached = x == preparedX_ && linear_.size() == springs_.size();
  ForColours([&](size_t j, const Spring& sp) {
    double len;
    const Linear l = cached ? linear_[j] : Linearise(sp, x, &len);
    const Vec3 u2 = Vec3(l.u[0], l.u[1], l.u[2]).cwiseAbs2();
    const Vec3 g = -cx * (Vec3::Constant(l.kt) + l.kl * u2) - cv * l.kd * u2;
    diag[l.a] += g;
    diag[l.b] += g;
  });
}

// --- system ---

System::System(int threads) {
  SetThreads(threads);
}
System::~System() {
  for (auto& f : forces_) TakeBackPool(*f);
}

void System::SetThreads(int threads) {
  for (auto& f : forces_) TakeBackPool(*f);
  pools_.SetThreads(threads);
  pool_ = pools_.pool();
  LendPool();
}

void System::UsePool(ThreadPool* pool) {
  for (auto& f : forces_) TakeBackPool(*f);
  pools_.UsePool(pool);
  pool_ = pools_.pool();
  LendPool();
}

int System::threads() const {
  return pools_.threads();
}

namespace {
std::atomic<uint64_t> gForceIds{0};  // the last handle made, over the process
}  // namespace

ForceHandle System::AddForce(std::shared_ptr<Force> f) {
  SYLVA_ASSERT(f != nullptr);
  f->set_pool(pool_);
  hasNonLocal_ |= !f->local();
  forces_.push_back(std::move(f));
  const uint64_t id = gForceIds.fetch_add(1) + 1;
  forceIds_.push_back(id);
  return {id};
}

size_t System::ForceIndex(ForceHandle handle) const {
  for (size_t k = 0; k < forceIds_.size(); ++k) {
    if (forceIds_[k] == handle.id && handle.id != 0) return k;
  }
  return SIZE_MAX;
}

Status System::HandleError(const char* what, ForceHandle handle) const {
  return check::Error(check::Cat(what, ": force handle ", std::to_string(handle.id),
                                 handle.id == 0 ? " is the default handle (no force)"
                                                : " names no force of this system (removed, "
                                                  "or another system's)"));
}

Force* System::force(ForceHandle handle) const {
  const size_t k = ForceIndex(handle);
  return k == SIZE_MAX ? nullptr : forces_[k].get();
}

void System::TakeBackPool(Force& f) const {
  if (f.pool() == pool_) f.set_pool(nullptr);
}

void System::LendPool() {
  for (auto& f : forces_) f->set_pool(pool_);
}

void System::UpdateLocality() {
  hasNonLocal_ = false;
  for (const auto& f : forces_) hasNonLocal_ |= !f->local();
}

Status System::ReplaceForce(ForceHandle handle, std::shared_ptr<Force> f) {
  const size_t k = ForceIndex(handle);
  if (k == SIZE_MAX) return HandleError("System.ReplaceForce", handle);
  if (!f) return check::Error("System.ReplaceForce: the new force is null");
  TakeBackPool(*forces_[k]);
  f->set_pool(pool_);
  forces_[k] = std::move(f);
  UpdateLocality();
  return {};
}

Status System::RemoveForce(ForceHandle handle) {
  const size_t k = ForceIndex(handle);
  if (k == SIZE_MAX) return HandleError("System.RemoveForce", handle);
  TakeBackPool(*forces_[k]);
  forces_.erase(forces_.begin() + std::ptrdiff_t(k));
  forceIds_.erase(forceIds_.begin() + std::ptrdiff_t(k));
  UpdateLocality();
  return {};
}

size_t System::RemoveDead() {
  ParticleState& s = state;
  const size_t removed = RemoveIf(
      s.size(), [&](size_t i) { return s.age[i] >= s.lifetime[i]; }, &remap_, s.position,
      s.velocity, s.mass, s.invMass, s.age, s.lifetime, s.color, s.radius, s.id);
  if (removed > 0) {
    for (auto& f : forces_) f->Renumber(remap_);
  }
  return removed;
}

Status System::AddCollider(Collider c) {
  SYLVA_CHECK_OK(Validate(c));
  colliders_.push_back(std::move(c));
  return {};
}

Status System::SetCollider(size_t index, Collider c) {
  if (index >= colliders_.size())
    return check::Error("System.SetCollider: collider " + std::to_string(index) + " of " +
                        std::to_string(colliders_.size()));
  SYLVA_CHECK_OK(Validate(c));
  colliders_[index] = std::move(c);
  return {};
}

Status System::EnableParticleCollisions(double radius, double restitution) {
  SYLVA_CHECK_OK(check::Range("System.EnableParticleCollisions radius", radius, 1e-12, 1e12, "m"));
  SYLVA_CHECK_OK(check::Range("System.EnableParticleCollisions restitution", restitution, 0, 1));
  pairRadius_ = radius;
  pairRestitution_ = restitution;
  if (!pairWork_) pairWork_ = std::make_unique<PairWork>();
  return {};
}

template <typename Fn>
void System::ForChunks(size_t n, Fn&& fn) const {
  // At most kChunk a range (the fused step's force buffer), balanced.
  if (!pool_) {
    for (size_t b = 0; b < n; b += kChunk) fn(b, std::min(n, b + kChunk));
    return;
  }
  ForRanges(pool_, n, BalancedGrain(pool_, n, 256, kChunk), fn);
}

void System::MoveColliders(double h) {
  for (Collider& c : colliders_) {
    if (c.moving()) c.Translate(h * c.velocity);
  }
}

void System::NonLocalForces(const Vec3* x, const Vec3* v) const {
  if (!hasNonLocal_) return;
  const size_t n = state.size();
  f_.resize(n);
  ForChunks(n,
            [&](size_t b, size_t e) { std::fill(f_.begin() + b, f_.begin() + e, Vec3::Zero()); });
  for (const auto& force : forces_) {
    if (!force->local()) force->Accumulate(state, x, v, f_.data());
  }
}

void System::LocalForcesInto(size_t b, size_t e, const Vec3* x, const Vec3* v, Vec3* fc) const {
  if (hasNonLocal_) {
    std::copy(f_.begin() + b, f_.begin() + e, fc);
  } else {
    std::fill(fc, fc + (e - b), Vec3::Zero());
  }
  for (const auto& force : forces_) {
    if (force->local())
      static_cast<const LocalForce&>(*force).AccumulateRange(state, x, v, fc, b, e);
  }
}

void System::Accelerations(const Vec3* x, const Vec3* v, Vec3* a) const {
  NonLocalForces(x, v);
  ForChunks(state.size(), [&](size_t b, size_t e) {
    LocalForcesInto(b, e, x, v, a + b);
    const double* w = state.invMass.data();
    for (size_t i = b; i < e; ++i) a[i] *= w[i];
  });
}

double System::KineticEnergy() const {
  return KineticEnergyOf(state.size(),
                         [&](size_t i) { return std::pair(state.invMass[i], state.velocity[i]); });
}

uint64_t System::Hash() const {
  BitHash h;
  for (const std::vector<Vec3>* a : {&state.position, &state.velocity}) {
    for (const Vec3& p : *a) {
      for (int k = 0; k < 3; ++k) h.Mix(p[k]);
    }
  }
  return h.value();
}

// Contact response for particle i (see RespondToContacts); kill and stick
// change its cold data.
[[gnu::noinline]] void System::Collide(size_t i, Vec3 a, Vec3 va, Vec3& x, Vec3& v, double h) {
  switch (RespondToContacts(colliders_, a, va, x, v, h, double(state.radius[i]))) {
    case ContactOutcome::kKilled:
      state.lifetime[i] = std::min(state.lifetime[i], state.age[i]);
      break;
    case ContactOutcome::kStuck:
      state.invMass[i] = 0;
      break;
    case ContactOutcome::kUnresolved:
      faults_.Unresolved(i);
      break;
    case ContactOutcome::kNone:
    case ContactOutcome::kResponded:
      break;
  }
}

[[gnu::always_inline]] inline void System::Finish(size_t i, const Vec3& x0, const Vec3& v0, Vec3 x1,
                                                  Vec3 v1, double h) {
  if (state.invMass[i] == 0) {  // immovable
    x1 = x0;
    v1 = Vec3::Zero();
  } else {
    const double r = double(state.radius[i]);
    for (const Collider& c : colliders_) {
      // A moving collider: the path in its frame at the start of the step.
      if (c.moving() ? c.MayHit(x0, x1 - h * c.velocity, r) : c.MayHit(x0, x1, r)) {
        Collide(i, x0, v0, x1, v1, h);
        break;
      }
    }
  }
  state.age[i] += h;
  if (!MaybeWithinLimit(x1, v1, faults_.limit2())) faults_.Flag();
  state.position[i] = x1;
  state.velocity[i] = v1;
}

void System::FlagBadRadii() {
  if (colliders_.empty() && pairRadius_ <= 0) return;  // no contact reads a radius
  const float* r = state.radius.data();
  const double limit2 = faults_.limit2();
  ForChunks(state.size(), [&](size_t b, size_t e) {
    if (const size_t i = BadRadiusIn(r, b, e, limit2); i != SIZE_MAX) faults_.BadRadius(i);
  });
}

Status System::CheckFaults(const char* what) {
  return faults_.Scan(what, state.step, state.time, state.size(), maxMagnitude, [&](size_t i) {
    return FaultLatch::Particle{state.id[i], state.position[i], state.velocity[i],
                                double(state.radius[i])};
  });
}

// x_ = X + c dx, out = V + c dv, for all particles: an RK stage's point.
void System::StagePoint(double c, const Vec3* dx, const Vec3* dv, Vec3* out) const {
  const Vec3* X = state.position.data();
  const Vec3* V = state.velocity.data();
  ForChunks(state.size(), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      x_[i] = X[i] + c * dx[i];
      out[i] = V[i] + c * dv[i];
    }
  });
}

Status System::CheckStep(const char* what, double h) {
  using namespace check;
  if (!(h > 0 && h <= 1e6))
    return Error(std::string(what) + " " + Num(h) + " is outside (0, 1e+06] s");
  SYLVA_CHECK_OK(Range("System.maxMagnitude", maxMagnitude, 1e-300, 1e300));
  SYLVA_CHECK_OK(Range("System.cgTolerance", cgTolerance, 0, 1));
  SYLVA_CHECK_OK(Range("System.cgMaxIterations", cgMaxIterations, 1, 1e7));
  SYLVA_CHECK_OK(Range("System.pairMaxPasses", pairMaxPasses, 16, 1e7));
  for (const auto& f : forces_) SYLVA_CHECK_OK(f->Check(state));
  SYLVA_CHECK_OK(CheckMasses(
      "System.Step", &state.massRecord, state.size(), [&](size_t i) { return state.mass[i]; },
      [&](size_t i) { return state.pinned(i); }, [&](size_t i) { return state.id[i]; }));
  LendPool();
  return {};
}

Status System::Step(double h, Integrator integrator) {
  if (faults_.fault()) return *faults_.fault();
  SYLVA_CHECK_OK(CheckStep("System.Step h", h));
  faults_.Begin(maxMagnitude);
  FlagBadRadii();
  const size_t n = state.size();
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  state.time = time;
  state.step = steps;
  if (pairRadius_ > 0) SavePairStart();
  switch (integrator) {
    case Integrator::kExplicitEuler:
    case Integrator::kSymplecticEuler: {
      // One fused pass a chunk: forces, integration, collisions.
      NonLocalForces(X.data(), V.data());
      const bool symplectic = integrator == Integrator::kSymplecticEuler;
      ForChunks(n, [&](size_t b, size_t e) {
        // On the stack (96 KiB): a step allocates nothing, on any thread.
        Vec3 fc[kChunk];
        LocalForcesInto(b, e, X.data(), V.data(), fc);
        const double* w = state.invMass.data();
        for (size_t i = b; i < e; ++i) {
          const Vec3 x0 = X[i], v0 = V[i];
          const Vec3 v1 = v0 + h * (fc[i - b] * w[i]);
          Finish(i, x0, v0, x0 + h * (symplectic ? v1 : v0), v1, h);
        }
      });
      break;
    }
    case Integrator::kMidpoint: {
      for (int k = 0; k < 2; ++k) k_[k].resize(n);
      x_.resize(n);
      v_.resize(n);
      Vec3 *a1 = k_[0].data(), *a2 = k_[1].data();
      Accelerations(X.data(), V.data(), a1);
      StagePoint(0.5 * h, V.data(), a1, v_.data());
      state.time = time + 0.5 * h;
      Accelerations(x_.data(), v_.data(), a2);
      ForChunks(n, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) Finish(i, X[i], V[i], X[i] + h * v_[i], V[i] + h * a2[i], h);
      });
      break;
    }
    case Integrator::kRK4: {
      for (int k = 0; k < 7; ++k) k_[k].resize(n);
      x_.resize(n);
      Vec3 *a1 = k_[0].data(), *a2 = k_[1].data(), *a3 = k_[2].data(), *a4 = k_[3].data();
      Vec3 *v2 = k_[4].data(), *v3 = k_[5].data(), *v4 = k_[6].data();
      Accelerations(X.data(), V.data(), a1);
      StagePoint(0.5 * h, V.data(), a1, v2);
      state.time = time + 0.5 * h;
      Accelerations(x_.data(), v2, a2);
      StagePoint(0.5 * h, v2, a2, v3);
      Accelerations(x_.data(), v3, a3);
      StagePoint(h, v3, a3, v4);
      state.time = time + h;
      Accelerations(x_.data(), v4, a4);
      ForChunks(n, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) {
          Finish(i, X[i], V[i], X[i] + h / 6 * (V[i] + 2 * v2[i] + 2 * v3[i] + v4[i]),
                 V[i] + h / 6 * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i]), h);
        }
      });
      break;
    }
    case Integrator::kImplicitEuler:
      SYLVA_CHECK_OK(ImplicitEuler(h));
      break;
  }
  if (pairRadius_ > 0) ParticleCollisions(h);
  MoveColliders(h);
  state.time = time;
  Status status = CheckFaults("in");
  if (status.ok() && pairRadius_ > 0 && !pairWork_->converged) status = PairPassesWarning("in");
  time += h;
  ++steps;
  return status;
}

template <int K, typename Fn>
std::array<double, K> System::SumChunks(size_t n, Fn&& fn) const {
  // Fixed chunks whatever the thread count: the partial sums, and so their
  // total, do not depend on it.
  constexpr size_t kSumChunk = 1024;
  const size_t chunks = (n + kSumChunk - 1) / kSumChunk;
  thread_local std::vector<std::array<double, K>> partial;
  std::vector<std::array<double, K>>& part = partial;  // the caller's, shared with the pool
  part.assign(chunks, std::array<double, K>{});
  ForRanges(pool_, chunks, BalancedGrain(pool_, chunks, 1), [&](size_t cb, size_t ce) {
    for (size_t c = cb; c < ce; ++c) part[c] = fn(c * kSumChunk, std::min(n, (c + 1) * kSumChunk));
  });
  std::array<double, K> sum{};
  for (const auto& p : part) {
    for (int k = 0; k < K; ++k) sum[size_t(k)] += p[size_t(k)];
  }
  return sum;
}

// Backward Euler linearised once about the current state (Baraff & Witkin
// 1998, eq. 16):
//   (M - h df/dv - h^2 df/dx) dv = h (f0 + h df/dx v0),
// solved matrix-free by Jacobi-preconditioned conjugate gradients;
// immovable particles are filtered out of the residual and the search
// direction. Vector passes run on the pool, fused, with sums in chunk order.
//
// Failures come back before anything moves: a non-finite right-hand side,
// preconditioner or product names the first particle where it is not finite
// (and faults the system, as an explosion does); a search direction with
// p.Ap <= 0 means the operator is not positive definite at this step (a
// force's Jacobian outweighs the masses), which a smaller step may cure.
Status System::ImplicitEuler(double h) {
  const size_t n = state.size();
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  for (auto& c : cg_) c.resize(n);
  Vec3 *b = cg_[0].data(), *r = cg_[1].data(), *p = cg_[2].data(), *q = cg_[3].data(),
       *dv = cg_[4].data();
  Vec3* inv = cg_[5].data();
  k_[0].resize(n);
  Vec3* a0 = k_[0].data();
  // Linearised first: springs then take their forces' lengths from it.
  for (const auto& f : forces_) f->PrepareJacobian(state, X.data(), V.data());
  Accelerations(X.data(), V.data(), a0);
  const double* m = state.mass.data();
  const double* w = state.invMass.data();
  ForChunks(n, [&](size_t bb, size_t e) {
    for (size_t i = bb; i < e; ++i) {
      b[i] = h * m[i] * a0[i];
      inv[i] = Vec3::Constant(m[i]);
    }
  });
  for (const auto& f : forces_)
    f->AddJacobianProduct(state, X.data(), V.data(), h * h, 0, V.data(), b);
  // Jacobi preconditioner: the inverse of the operator's diagonal.
  for (const auto& f : forces_) f->AddJacobianDiagonal(state, X.data(), V.data(), -h * h, -h, inv);
  // dv = 0, r = b (filtered), p = M^-1 r, q = A p's mass term.
  // A movable particle's diagonal must be positive and finite (counted in
  // s[2] otherwise).
  const auto start = SumChunks<3>(n, [&](size_t bb, size_t e) {
    std::array<double, 3> s{};
    for (size_t i = bb; i < e; ++i) {
      for (int k = 0; k < 3; ++k) {
        if (w[i] == 0) {
          inv[i][k] = 0;
          continue;
        }
        s[2] += !(inv[i][k] > 0 && inv[i][k] <= DBL_MAX);
        inv[i][k] = 1 / inv[i][k];
      }
      if (w[i] == 0) b[i] = Vec3::Zero();
      dv[i] = Vec3::Zero();
      r[i] = b[i];
      p[i] = r[i].cwiseProduct(inv[i]);
      q[i] = m[i] * p[i];
      s[0] += r[i].dot(p[i]);
      s[1] += b[i].squaredNorm();
    }
    return s;
  });
  double rz = start[0];
  const double bnorm = std::sqrt(start[1]);
  solve_ = {0, 0};
  if (!(bnorm <= DBL_MAX)) return NonFiniteSolve("right-hand side h (f + h df/dx v)", b, 0);
  if (start[2] > 0) {
    size_t i = 0;
    while (i < n && (w[i] == 0 || ((inv[i].array() > 0).all() && inv[i].allFinite()))) ++i;
    // The inverse is NaN or 0 where the diagonal is NaN or infinite.
    if (i == n || inv[i].hasNaN() || (inv[i].array() == 0).any())
      return NonFiniteSolve("diagonal", inv, 0);
    std::ostringstream o;
    o << "particles: in step " << state.step << " (from t = " << state.time
      << " s): the implicit Euler system M - h df/dv - h^2 df/dx is not positive definite (its "
         "diagonal at particle id "
      << state.id[i] << " has inverse " << Format(inv[i]) << ") at h = " << h
      << " s; try a smaller step; nothing moved";
    Diagnostic d = MakeError({}, o.str());
    d.kind = ErrorKind::kRuntime;
    return d;
  }
  if (bnorm > 0) {
    // The iterations' vector passes run on the flat arrays of 3n doubles
    // (kernels.h). Pinned particles take no part: q is zero there.
    const size_t n3 = 3 * n;
    double *pf = p[0].data(), *qf = q[0].data(), *rf = r[0].data(), *dvf = dv[0].data();
    const double* zf = inv[0].data();
    mass3_.resize(n3);
    pinned_.clear();
    for (size_t i = 0; i < n; ++i) {
      for (size_t k = 0; k < 3; ++k) mass3_[3 * i + k] = m[i];
      if (w[i] == 0) pinned_.push_back(i);
    }
    const double* m3 = mass3_.data();
    double rnorm = bnorm;
    int it = 0;
    while (it < cgMaxIterations && rnorm > cgTolerance * bnorm) {
      for (const auto& f : forces_)
        f->AddJacobianProduct(state, X.data(), V.data(), -h * h, -h, p, q);
      for (size_t i : pinned_) q[i] = Vec3::Zero();
      const double pq = SumChunks<1>(n3, [&](size_t bb, size_t e) {
        return std::array<double, 1>{kernels::Dot(kernel_, pf, qf, bb, e)};
      })[0];
      if (!(std::abs(pq) <= DBL_MAX)) return NonFiniteSolve("product A p", q, it);
      if (!(pq > 0)) {
        std::ostringstream o;
        o << "particles: in step " << state.step << " (from t = " << state.time
          << " s): the implicit Euler system M - h df/dv - h^2 df/dx is not positive definite "
             "(p.Ap = "
          << pq << " at conjugate-gradient iteration " << it
          << "): a force's Jacobian outweighs the masses at h = " << h
          << " s; try a smaller step; nothing moved";
        Diagnostic d = MakeError({}, o.str());
        d.kind = ErrorKind::kRuntime;
        return d;
      }
      const double alpha = rz / pq;
      const auto sums = SumChunks<2>(n3, [&](size_t bb, size_t e) {
        const kernels::CgSums c = kernels::CgStep(kernel_, alpha, pf, qf, zf, dvf, rf, bb, e);
        return std::array<double, 2>{c.rz, c.rr};
      });
      const double beta = sums[0] / rz;
      rz = sums[0];
      rnorm = std::sqrt(sums[1]);
      if (!(rnorm <= DBL_MAX && std::abs(rz) <= DBL_MAX)) return NonFiniteSolve("residual", r, it);
      ++it;
      if (it < cgMaxIterations && rnorm > cgTolerance * bnorm) {
        ForRanges(pool_, n3, BalancedGrain(pool_, n3, 1536, 3 * kChunk), [&](size_t bb, size_t e) {
          for (size_t k = bb; k < e; ++k) {
            pf[k] = rf[k] * zf[k] + beta * pf[k];
            qf[k] = m3[k] * pf[k];
          }
        });
      }
    }
    solve_ = {it, rnorm / bnorm};
  }
  ForChunks(n, [&](size_t bb, size_t e) {
    for (size_t i = bb; i < e; ++i) {
      const Vec3 v1 = V[i] + dv[i];
      Finish(i, X[i], V[i], X[i] + h * v1, v1, h);
    }
  });
  return {};
}

Status System::NonFiniteSolve(const char* what, const Vec3* a, int iteration) {
  size_t i = 0;
  while (i < state.size() && a[i].allFinite()) ++i;
  std::ostringstream o;
  o << "particles: in step " << state.step << " (from t = " << state.time
    << " s): implicit Euler's " << what << " is not finite";
  if (i < state.size()) o << " at particle id " << state.id[i] << ": " << Format(a[i]);
  o << " (conjugate-gradient iteration " << iteration
    << "); a force or its Jacobian is not finite; nothing moved";
  Diagnostic d = MakeError({}, o.str());
  d.kind = ErrorKind::kRuntime;
  return faults_.Latch(d);
}

void System::SavePairStart() {
  pairWork_->x0.assign(state.position.begin(), state.position.end());
  pairWork_->v0.assign(state.velocity.begin(), state.velocity.end());
}

// Dormand & Prince (1980) RK5(4)7M.
Status System::StepAdaptive(double dt, const AdaptiveOptions& opt, AdaptiveStats* stats) {
  if (faults_.fault()) return *faults_.fault();
  SYLVA_CHECK_OK(CheckStep("System.StepAdaptive dt", dt));
  faults_.Begin(maxMagnitude);  // the radii: at the accepted attempt, where contacts run
  SYLVA_CHECK_OK(check::Range("AdaptiveOptions.rtol", opt.rtol, 0, 1));
  SYLVA_CHECK_OK(check::Range("AdaptiveOptions.atol", opt.atol, 0, 1e12));
  if (!(opt.rtol > 0 || opt.atol > 0))
    return check::Error("AdaptiveOptions.rtol and atol are both 0");
  SYLVA_CHECK_OK(check::Range("AdaptiveOptions.minStep", opt.minStep, 1e-300, dt, "s (up to dt)"));
  SYLVA_CHECK_OK(check::Range("AdaptiveOptions.maxSteps", opt.maxSteps, 1, 1e9));
  static constexpr double c[7] = {0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1, 1};
  static constexpr double A[7][6] = {
      {},
      {1.0 / 5},
      {3.0 / 40, 9.0 / 40},
      {44.0 / 45, -56.0 / 15, 32.0 / 9},
      {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
      {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
      {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
  static constexpr double B5[7] = {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784,
                                   11.0 / 84,  0};
  static constexpr double B4[7] = {
      5179.0 / 57600, 0, 7571.0 / 16695, 393.0 / 640, -92097.0 / 339200, 187.0 / 2100, 1.0 / 40};
  AdaptiveStats local;
  AdaptiveStats& st = stats ? *stats : local;
  const size_t n = state.size();
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  for (int k = 0; k < 14; ++k) k_[k].resize(n);
  x_.resize(n);
  v_.resize(n);
  Vec3* KX[7];
  Vec3* KV[7];
  for (int k = 0; k < 7; ++k) {
    KX[k] = k_[k].data();
    KV[k] = k_[7 + k].data();
  }
  const double tEnd = time + dt;
  double h = adaptiveStep_ > 0 ? std::min(adaptiveStep_, dt) : dt;
  int calls = 0;
  std::optional<Diagnostic> warning;  // the first substep whose gas contacts did not converge
  while (time < tEnd && tEnd - time > 1e-14 * std::max(1.0, std::abs(tEnd))) {
    if (++calls > opt.maxSteps) {
      Diagnostic d = MakeError({}, "particles: adaptive RK45 needed more than " +
                                       std::to_string(opt.maxSteps) + " steps for " +
                                       std::to_string(dt) + " s");
      d.kind = ErrorKind::kRuntime;
      return d;
    }
    h = std::min(h, tEnd - time);
    state.step = steps;
    for (int s = 0; s < 7; ++s) {
      const Vec3* xs = X.data();
      const Vec3* vs = V.data();
      if (s > 0) {
        ForChunks(n, [&](size_t b, size_t e) {
          for (size_t i = b; i < e; ++i) {
            Vec3 dx = Vec3::Zero(), dvv = Vec3::Zero();
            for (int l = 0; l < s; ++l) {
              dx += A[s][l] * KX[l][i];
              dvv += A[s][l] * KV[l][i];
            }
            x_[i] = X[i] + h * dx;
            v_[i] = V[i] + h * dvv;
          }
        });
        xs = x_.data();
        vs = v_.data();
      }
      state.time = time + c[s] * h;
      std::copy(vs, vs + n, KX[s]);
      Accelerations(xs, vs, KV[s]);
    }
    // x_, v_ hold the 7th stage point, which is the fifth-order solution.
    // The error norm: the largest scaled component. A NaN or an infinity in
    // any component is a fault of that particle, never a maximum that
    // drops it.
    double err = 0;
    for (size_t i = 0; i < n; ++i) {
      Vec3 ex = Vec3::Zero(), ev = Vec3::Zero();
      for (int l = 0; l < 7; ++l) {
        ex += (B5[l] - B4[l]) * KX[l][i];
        ev += (B5[l] - B4[l]) * KV[l][i];
      }
      double ei = 0;
      for (int k = 0; k < 3; ++k) {
        const double sx = opt.atol + opt.rtol * std::max(std::abs(X[i][k]), std::abs(x_[i][k]));
        const double sv = opt.atol + opt.rtol * std::max(std::abs(V[i][k]), std::abs(v_[i][k]));
        const double cx = std::abs(h * ex[k]) / sx, cv = std::abs(h * ev[k]) / sv;
        ei = cx > ei ? cx : ei;
        ei = cv > ei ? cv : ei;
        if (!(cx <= DBL_MAX && cv <= DBL_MAX && x_[i].allFinite() && v_[i].allFinite())) {
          Diagnostic fault = ExplosionDiagnostic("in adaptive", steps, time, state.id[i], x_[i],
                                                 v_[i], maxMagnitude);
          if (x_[i].allFinite() && v_[i].allFinite()) {
            fault.message = "particles: in adaptive step " + std::to_string(steps) +
                            " (from t = " + check::Num(time) + " s): particle id " +
                            std::to_string(state.id[i]) + " has an error estimate (" +
                            check::Num(h * ex[k]) + " m, " + check::Num(h * ev[k]) +
                            " m/s) that is not finite; the forces are not finite";
          }
          return faults_.Latch(fault);
        }
      }
      err = std::max(err, ei);
    }
    if (err <= 1) {
      faults_.Begin(maxMagnitude);
      FlagBadRadii();
      if (pairRadius_ > 0) SavePairStart();
      ForChunks(n, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) Finish(i, X[i], V[i], x_[i], v_[i], h);
      });
      if (pairRadius_ > 0) ParticleCollisions(h);
      MoveColliders(h);
      state.time = time;
      Status s = CheckFaults("in adaptive");
      if (s.ok() && pairRadius_ > 0 && !pairWork_->converged && !warning)
        warning = PairPassesWarning("in adaptive").error();
      time += h;
      ++steps;
      ++st.accepted;
      st.maxError = std::max(st.maxError, err);
      if (!s.ok()) return s;
    } else {
      ++st.rejected;
    }
    const double factor = err == 0 ? 5 : std::clamp(0.9 * std::pow(err, -0.2), 0.2, 5.0);
    h *= factor;
    if (!(h >= opt.minStep)) {
      std::ostringstream o;
      o << "particles: adaptive RK45 step fell below " << opt.minStep << " s at t = " << time
        << " s (error norm " << err << "); the forces are too stiff or not finite";
      Diagnostic d = MakeError({}, o.str());
      d.kind = ErrorKind::kRuntime;
      return faults_.Latch(d);
    }
  }
  adaptiveStep_ = h;
  st.lastStep = h;
  if (warning) return *warning;
  return {};
}

}  // namespace sylva::particles
