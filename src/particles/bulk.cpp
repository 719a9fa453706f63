#include "particles/bulk.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <optional>

#include "particles/def_check.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

// Particles a chunk: the chunk's previous state (6 floats a particle) and
// candidate flags stay in L1.
constexpr size_t kChunk = 512;
static_assert(kChunk <= kernels::kRestRange);

Vec3f Round(const Vec3& x) {
  return Vec3f(float(x.x()), float(x.y()), float(x.z()));
}

// How many single-precision roundings of the largest coordinate a
// resting particle's start may lie from the exact answer and be kept
// (RoundOutside).
using kernels::kRestPush;
using kernels::kRestRoundings;

// How far above a plane a particle's start still rests on it
// (RespondToContacts' skin): kRestSkin of its largest coordinate, at least
// 1; twice RoundOutside's push, so that a particle the push left above a
// plane rests on it the next step (the floor's kernel takes the same).
double StartSkin(const Vec3& a) {
  return kernels::kRestSkin * std::max(1.0, a.cwiseAbs().maxCoeff());
}

// Whether the rounded point r lies across, or on, a collider as seen from x:
// the rounding's displacement, doubled (a rounded point exactly on a thin
// surface counts as across it: from there a path could leave on either
// side). The crossing's normal in *normal.
bool Crosses(const std::vector<Collider>& colliders, const Vec3& x, const Vec3& r, double radius,
             double h, MeshMemo* memo, Vec3* normal) {
  const Vec3 beyond = r + (r - x);
  for (const Collider& c : colliders) {
    Contact ct;
    const Vec3 w = h * c.velocity;  // where a moving collider ends the step
    if (c.Intersect(x - w, beyond - w, &ct, radius, memo)) {
      *normal = ct.normal;
      return true;
    }
  }
  return false;
}

// x rounded to single precision on the side of every collider that x (the
// double-precision contact response) is on: rounding a point on a surface
// may move it across or onto it (thin panels and meshes have a skin of only
// 1e-9 relative), and a particle must never end a step behind a surface, nor
// on a thin one, where the next step could not tell its side. A rounded
// point that crosses or touches one is pushed off it along the contact
// normal by a few single-precision ulps and rounded again.
//
// Where x's nearest floats cross a surface and the contact response left
// the particle at rest (static friction held it: its velocity is exactly
// zero), the floats it started the step with (`start`) serve instead, if
// they lie within kRestRoundings of x in every coordinate and on x's side
// of every collider: as good a rounding of the exact answer as the push
// (which alone moves a point by 4 ulps of its largest coordinate), and a
// resting particle then stays exactly where it is. Before, a flake at rest
// on a slope started each step a few ulps above the surface where the push
// had left it, dropped back onto it along its path (which leans downhill
// with gravity and the wind), was pushed up again, and so crept downhill by
// a few ulps a step for ever.
Vec3f RoundOutside(const std::vector<Collider>& colliders, const Vec3& x, double radius, double h,
                   MeshMemo* memo, const Vec3f* start) {
  const double scale = double(FLT_EPSILON) * std::max(1.0, x.cwiseAbs().maxCoeff());
  Vec3f xf = Round(x);
  const double push = kRestPush * scale;
  Vec3 base = x, normal;
  for (int tries = 0; tries < 4; ++tries) {
    const Vec3 r = xf.cast<double>();
    if (r == x) return xf;
    if (!Crosses(colliders, x, r, radius, h, memo, &normal)) return xf;
    if (tries == 0 && start) {
      const Vec3 s = start->cast<double>();
      Vec3 unused;
      if ((s - x).cwiseAbs().maxCoeff() <= kRestRoundings * scale &&
          !Crosses(colliders, x, s, radius, h, memo, &unused)) {
        return *start;
      }
    }
    base += push * normal;
    xf = Round(base);
  }
  return xf;
}

}  // namespace

uint32_t BulkState::Add(const Vec3& p, const Vec3& v, double m, double life) {
  px.push_back(float(p.x()));
  py.push_back(float(p.y()));
  pz.push_back(float(p.z()));
  vx.push_back(float(v.x()));
  vy.push_back(float(v.y()));
  vz.push_back(float(v.z()));
  invMass.push_back(float(InverseMassOf(m, nextId, &massRecord)));
  birth.push_back(float(time));
  lifetime.push_back(float(std::min(life, 1e30)));
  color.push_back(Vec3f(1, 1, 1));
  radius.push_back(0.0f);
  id.push_back(nextId);
  return nextId++;
}

uint32_t BulkState::AddPinned(const Vec3& p, double life) {
  const uint32_t added = Add(p, Vec3::Zero(), 1, life);
  Pin(size() - 1);
  return added;
}

void BulkState::SetPosition(size_t i, const Vec3& p) {
  px[i] = float(p.x());
  py[i] = float(p.y());
  pz[i] = float(p.z());
}

void BulkState::SetVelocity(size_t i, const Vec3& v) {
  vx[i] = float(v.x());
  vy[i] = float(v.y());
  vz[i] = float(v.z());
}

void BulkState::Reserve(size_t n) {
  for (auto* a : FloatArrays()) a->reserve(n);
  color.reserve(n);
  id.reserve(n);
}

BulkSystem::BulkSystem(int threads) {
  SetThreads(threads);
}
BulkSystem::~BulkSystem() = default;

void BulkSystem::SetThreads(int threads) {
  pools_.SetThreads(threads);
}

void BulkSystem::UsePool(ThreadPool* pool) {
  pools_.UsePool(pool);
}

int BulkSystem::threads() const {
  return pools_.threads();
}

void BulkSystem::StepRange(size_t begin, size_t end, double h, const kernels::BulkParams& q,
                           bool sleep) {
  BulkState& s = state;
  const kernels::BulkArrays a{s.px.data(), s.py.data(), s.pz.data(),     s.vx.data(),
                              s.vy.data(), s.vz.data(), s.invMass.data()};
  alignas(32) float old[6][kChunk];
  float* const olds[6] = {old[0], old[1], old[2], old[3], old[4], old[5]};
  alignas(32) uint8_t flags[kChunk];
  uint16_t idx[kChunk + 4];
  uint16_t near[kChunk];
  // The vector path for resting contact: one static plane that bounces.
  std::optional<kernels::PlaneRest> floorRest;
  if (restLanes_ > 0 && colliders_.size() == 1 && colliders_[0].kind == Collider::Kind::kPlane &&
      !colliders_[0].moving() && colliders_[0].response == Response::kBounce) {
    const Collider& f = colliders_[0];
    floorRest = kernels::PlaneRest{{f.normal.x(), f.normal.y(), f.normal.z()},
                                   {f.point.x(), f.point.y(), f.point.z()},
                                   f.friction,
                                   h,
                                   faults_.limit2()};
  }
  const kernels::PlaneRest* floor = floorRest ? &*floorRest : nullptr;
  // A lone static plane lists its candidates directly.
  const Collider* plane = colliders_.size() == 1 && colliders_[0].kind == Collider::Kind::kPlane &&
                                  !colliders_[0].moving()
                              ? &colliders_[0]
                              : nullptr;
  for (size_t c = begin; c < end; c += kChunk) {
    const size_t ce = std::min(end, c + kChunk), m = ce - c;
    size_t count = 0;
    // A bad radius (see BadRadiusIn) is reported after the step: the
    // floor's kernel checks the radii it loads anyway (a scan of its own
    // cost that path 12 %), the other paths scan the chunk's.
    auto checkRadii = [&] {
      if (const size_t i = BadRadiusIn(s.radius.data(), c, ce, faults_.limit2()); i != SIZE_MAX)
        faults_.BadRadius(i);
    };
    if (floor) {
      // A lone static floor: the advance and the floor's candidates, then
      // its resting contacts, over the chunk; what is left of the
      // candidates to the general path below.
      bool ok = true;
      count = kernels::BulkAdvanceRestOnPlane(restLanes_, q, *floor, a, s.radius.data(), c, ce,
                                              olds, idx, &ok);
      if (!ok) {
        faults_.Flag();
        checkRadii();
      }
    } else {
      if (!kernels::BulkAdvance(kernel_, q, a, c, ce, olds)) faults_.Flag();
      if (colliders_.empty()) continue;  // no contact reads a radius
      checkRadii();
      if (plane) {
        count = kernels::BulkPlaneCandidateList(kernel_, plane->normal.data(), plane->point.data(),
                                                a, s.radius.data(), c, ce, idx);
      } else {
        std::memset(flags, 0, m);
        // The sleepers: back to the state they started the step in (see
        // BulkSystem::Still), and no collider sees them.
        if (sleep) {
          size_t slept = 0;
          for (size_t j = 0; j < m; ++j) {
            if (!asleep_[c + j]) continue;
            const Still& st = still_[c + j];
            const float now[8] = {old[0][j], old[1][j], old[2][j],       old[3][j],
                                  old[4][j], old[5][j], s.radius[c + j], s.invMass[c + j]};
            if (std::memcmp(now, &st, sizeof now) != 0) {
              asleep_[c + j] = 0;
              continue;
            }
            s.px[c + j] = st.s[0], s.py[c + j] = st.s[1], s.pz[c + j] = st.s[2];
            s.vx[c + j] = st.s[3], s.vy[c + j] = st.s[4], s.vz[c + j] = st.s[5];
            flags[j] = 2;
            ++slept;
          }
          sleepers_.fetch_add(slept, std::memory_order_relaxed);
        }
        for (const Collider& col : colliders_) {
          if (col.kind == Collider::Kind::kPlane && !col.moving()) {
            kernels::BulkPlaneCandidates(kernel_, col.normal.data(), col.point.data(), a,
                                         s.radius.data(), c, ce, flags);
            continue;
          }
          // Any other collider (a moving one: the path in its frame at the
          // start of the step).
          const Vec3 shift = h * col.velocity;
          if (col.kind == Collider::Kind::kMesh && col.mesh && !memos_.empty()) {
            // A mesh: its memo-free screen first (most flakes are in the
            // air), then its full screen for the rest, their memos (112
            // bytes each, of an array of them all) fetched eight ahead.
            size_t kept = 0;
            for (size_t j = 0; j < m; ++j) {
              if (flags[j] & 2) continue;  // asleep
              const Vec3 from(old[0][j], old[1][j], old[2][j]);
              if (!col.mesh->Clear(from - col.offset, s.position(c + j) - shift - col.offset,
                                   double(s.radius[c + j])))
                near[kept++] = uint16_t(j);
            }
            for (size_t k = 0; k < kept; ++k) {
              if (k + 8 < kept) __builtin_prefetch(&memos_[c + near[k + 8]]);
              const size_t j = near[k];
              flags[j] |=
                  col.MayHit(Vec3(old[0][j], old[1][j], old[2][j]), s.position(c + j) - shift,
                             double(s.radius[c + j]), &memos_[c + j]);
            }
            continue;
          }
          for (size_t j = 0; j < m; ++j) {
            if (flags[j] & 2) continue;  // asleep
            flags[j] |=
                col.MayHit(Vec3(old[0][j], old[1][j], old[2][j]), s.position(c + j) - shift,
                           double(s.radius[c + j]), memos_.empty() ? nullptr : &memos_[c + j]);
          }
        }
        // The candidates, in order; eight flags at a time (most particles
        // touch nothing).
        for (size_t j = 0; j < m; ++j) {
          if (j % 8 == 0 && j + 8 <= m) {
            uint64_t word;
            std::memcpy(&word, flags + j, 8);
            if (word == 0) {
              j += 7;
              continue;
            }
          }
          if (flags[j] == 1 && s.invMass[c + j] != 0) idx[count++] = uint16_t(j);
        }
      }
    }
    for (size_t k = 0; k < count; ++k) {
      const size_t j = idx[k], i = c + j;
      Vec3 x = s.position(i), v = s.velocity(i);
      const double r = double(s.radius[i]);
      MeshMemo* const memo = memos_.empty() ? nullptr : &memos_[i];
      const Vec3 start(old[0][j], old[1][j], old[2][j]);
      const ContactOutcome out =
          RespondToContacts(colliders_, start, Vec3(old[3][j], old[4][j], old[5][j]), x, v, h, r,
                            memo, StartSkin(start));
      if (out == ContactOutcome::kNone) continue;
      if (out == ContactOutcome::kKilled) {
        // Dies at its age at the start of the step (rounded down), so it is
        // dead at the end whatever the rounding.
        const double age = s.age(i);
        float life = float(age);
        if (double(life) > age) life = std::nextafter(life, 0.0f);
        s.lifetime[i] = std::min(s.lifetime[i], life);
      }
      if (out == ContactOutcome::kStuck) s.invMass[i] = 0;
      if (out == ContactOutcome::kUnresolved) faults_.Unresolved(i);
      // At rest after a resting contact (see RoundOutside): the start's
      // floats where they round x as well.
      const Vec3f startf(old[0][j], old[1][j], old[2][j]);
      const bool rest = out == ContactOutcome::kResponded && v == Vec3::Zero();
      const Vec3f xf = RoundOutside(colliders_, x, r, h, memo, rest ? &startf : nullptr);
      s.px[i] = xf.x(), s.py[i] = xf.y(), s.pz[i] = xf.z();
      s.SetVelocity(i, v);
      const bool within = MaybeWithinLimit(xf.cast<double>(), v, faults_.limit2());
      if (!within) faults_.Flag();
      if (sleep && out == ContactOutcome::kResponded && within) {
        // Unchanged by the step: asleep from the next one on.
        Still st{{s.px[i], s.py[i], s.pz[i], s.vx[i], s.vy[i], s.vz[i]}, s.radius[i], s.invMass[i]};
        const float before[6] = {old[0][j], old[1][j], old[2][j], old[3][j], old[4][j], old[5][j]};
        if (std::memcmp(before, st.s, sizeof before) == 0) {
          still_[i] = st;
          asleep_[i] = 1;
        }
      }
    }
  }
}

Status Validate(const BulkFields& f) {
  using namespace check;
  SYLVA_CHECK_OK(Finite("BulkFields.gravity", f.gravity, 1e12, "m/s^2"));
  SYLVA_CHECK_OK(Range("BulkFields.linearDrag", f.linearDrag, 0, 1e12, "N s/m"));
  SYLVA_CHECK_OK(Range("BulkFields.quadraticDrag", f.quadraticDrag, 0, 1e12, "N s^2/m^2"));
  SYLVA_CHECK_OK(Finite("BulkFields.wind", f.wind, 1e12, "m/s"));
  return {};
}

Status BulkSystem::AddCollider(Collider c) {
  SYLVA_CHECK_OK(Validate(c));
  colliders_.push_back(std::move(c));
  std::fill(asleep_.begin(), asleep_.end(), 0);  // new inputs: everyone awake
  return {};
}

Status BulkSystem::Step(double h) {
  if (faults_.fault()) return *faults_.fault();
  if (!(h > 0 && h <= 1e6))
    return check::Error("BulkSystem.Step h " + check::Num(h) + " is outside (0, 1e+06] s");
  SYLVA_CHECK_OK(check::Range("BulkSystem.maxMagnitude", maxMagnitude, 1e-30, 1e300));
  SYLVA_CHECK_OK(Validate(fields));
  SYLVA_CHECK_OK(CheckMasses(
      "BulkSystem.Step", &state.massRecord, state.size(),
      [&](size_t i) { return 1 / double(state.invMass[i]); },
      [&](size_t i) { return state.pinned(i); }, [&](size_t i) { return state.id[i]; }));
  const Vec3& g = fields.gravity;
  const Vec3& w = fields.wind;
  // Rounded toward zero: a component above maxMagnitude must not pass the
  // float check unflagged (the flagged are checked again in double).
  float limit = float(std::min(maxMagnitude, double(FLT_MAX)));
  if (double(limit) > maxMagnitude) limit = std::nextafter(limit, 0.0f);
  const kernels::BulkParams q{float(g.x()),
                              float(g.y()),
                              float(g.z()),
                              float(w.x()),
                              float(w.y()),
                              float(w.z()),
                              float(fields.linearDrag),
                              float(fields.quadraticDrag),
                              float(h),
                              limit};
  faults_.Begin(maxMagnitude);
  const size_t n = state.size();
  // A memo a particle for the mesh queries (kept by index: after RemoveDead
  // one may serve another particle, which is safe, only slower once).
  const bool meshes = std::any_of(colliders_.begin(), colliders_.end(), [](const Collider& c) {
    return c.kind == Collider::Kind::kMesh;
  });
  if (meshes && meshMemos_ && memos_.size() != n) memos_.resize(n);
  // Sleeping (see Still): where the step takes the general contact path
  // (not a lone static plane's) and no collider moves. The step's inputs
  // as bits; any change wakes every particle.
  const bool lonePlane = colliders_.size() == 1 && colliders_[0].kind == Collider::Kind::kPlane;
  const bool sleep = sleeping_ && !colliders_.empty() && !lonePlane &&
                     std::none_of(colliders_.begin(), colliders_.end(),
                                  [](const Collider& c) { return c.moving(); });
  sleepers_.store(0, std::memory_order_relaxed);
  if (sleep) {
    std::array<uint64_t, 8> key{};
    static_assert(sizeof q <= 6 * sizeof(uint64_t));
    std::memcpy(key.data(), &q, sizeof q);
    const double limit2 = faults_.limit2();
    std::memcpy(&key[6], &limit2, sizeof limit2);
    key[7] = uint64_t(colliders_.size());
    if (key != key_ || asleep_.size() != n) {
      // Records are kept by index (after RemoveDead one may face another
      // particle: its floats, radius and inverse mass decide, so that is
      // safe), but new inputs wake everyone.
      if (key != key_) std::fill(asleep_.begin(), asleep_.end(), 0);
      asleep_.resize(n, 0);
      still_.resize(n);
      key_ = key;
    }
  }
  ThreadPool* const pool = pools_.pool();
  // Ranges of whole chunks, a few a thread.
  const size_t grain = (BalancedGrain(pool, n, kChunk, 64 * kChunk) + kChunk - 1) / kChunk * kChunk;
  // Contacts see the step the kernel took (h rounded to a float).
  ForRanges(pool, n, grain, [&](size_t b, size_t e) { StepRange(b, e, double(q.h), q, sleep); });
  for (Collider& c : colliders_) {
    if (c.moving()) c.Translate(double(q.h) * c.velocity);
  }
  Status status = Fault();
  state.time += h;
  ++steps;
  return status;
}

Status BulkSystem::Fault() {
  return faults_.Scan("in bulk", steps, state.time, state.size(), maxMagnitude, [&](size_t i) {
    return FaultLatch::Particle{state.id[i], state.position(i), state.velocity(i),
                                double(state.radius[i])};
  });
}

size_t BulkSystem::Append(const ParticleState& born, size_t begin) {
  const size_t n = born.size();
  if (begin >= n) return 0;
  // Geometric growth: reserving exactly what is appended would copy every
  // array on every call (quadratic over many small births).
  const size_t need = state.size() + (n - begin);
  if (need > state.px.capacity()) state.Reserve(std::max(need, 2 * state.px.capacity()));
  if (born.massRecord.bad && !state.massRecord.bad) state.massRecord = born.massRecord;
  for (size_t i = begin; i < n; ++i) {
    const Vec3 &p = born.position[i], &v = born.velocity[i];
    state.px.push_back(float(p.x()));
    state.py.push_back(float(p.y()));
    state.pz.push_back(float(p.z()));
    state.vx.push_back(float(v.x()));
    state.vy.push_back(float(v.y()));
    state.vz.push_back(float(v.z()));
    state.invMass.push_back(float(born.invMass[i]));
    state.birth.push_back(float(state.time - born.age[i]));
    state.lifetime.push_back(float(std::min(born.lifetime[i], 1e30)));
    state.color.push_back(born.color[i]);
    state.radius.push_back(born.radius[i]);
    state.id.push_back(born.id[i]);
    state.nextId = std::max(state.nextId, born.id[i] + 1);
  }
  return n - begin;
}

size_t BulkSystem::RemoveDead() {
  BulkState& s = state;
  return RemoveIf(
      s.size(), [&](size_t i) { return s.dead(i); }, nullptr, s.px, s.py, s.pz, s.vx, s.vy, s.vz,
      s.invMass, s.birth, s.lifetime, s.color, s.radius, s.id);
}

double BulkSystem::KineticEnergy() const {
  return KineticEnergyOf(state.size(), [&](size_t i) {
    return std::pair(double(state.invMass[i]), state.velocity(i));
  });
}

uint64_t BulkSystem::Hash() const {
  BitHash h;
  for (size_t i = 0; i < state.size(); ++i) {
    for (float c : {state.px[i], state.py[i], state.pz[i], state.vx[i], state.vy[i], state.vz[i]})
      h.Mix(c);
  }
  return h.value();
}

}  // namespace sylva::particles
