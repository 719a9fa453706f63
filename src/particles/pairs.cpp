// Particle-particle contacts of System (EnableParticleCollisions): swept
// spheres, solved in parallel by symmetric Jacobi passes.
//
// Detection is continuous. Over a step particle i moves along the chord
// x0_i -> x1_i; two particles touch when their centres' relative chord
// d(t) = d0 + t dd first reaches |d| = r_i + r_j, t in [0, 1] (the root of a
// quadratic; t = 0 when they start overlapping). Candidates come from a
// grid over the start positions with a reach of twice the largest radius
// plus twice the largest displacement of the step, so a pair moving fast
// toward each other is found however far it travels (the cost grows with
// the fastest particle's step). The contact keeps the normal at the time
// of impact and its target speed (from the relative normal speed before
// the solve).
//
// Layout (pairs.h). The work runs in the grid's slot order: each
// particle's data is copied there once a step, so neighbours are near in
// memory, and written back at the end. One walk of the grid finds the
// contacts, each pair once: each particle looks through half of its
// neighbourhood (NeighbourGrid::ForEachHalfCandidateRange), screens the
// candidates by distance without a branch into a small buffer, and
// appends the contacts it finds (it owns them; the other ball is the
// partner) to its chunk's array (kPairChunk particles a chunk, the unit of
// parallel work), so no counting pass is needed. A counting sort by
// partner then lists, for each particle, the contacts where it is the
// partner (PairWork::pushFrom). A pass computes each contact once, by its
// owner, adds it to the owner's sum and stores it (negated by the partner)
// in the contacts' order; then each particle adds up the pushes its list
// names, in one sweep (each thread writes only its own chunks' pushes:
// writing them into the partners' runs shared cache lines between the
// threads). (Each particle kept a mirror image of
// each of its contacts before: twice the time of impact, twice the passes'
// work and memory.) The velocity passes take the positive part of an
// impulse without a branch (its sign changes from pass to pass: a branch
// on it was mispredicted often enough to cost half the pass).
//
// Response, in two kinds of passes over the contacts (found in the grid's
// order, and each particle's sums in a fixed order: the same whatever the
// thread count):
//   velocity  a contact whose approach is faster than the step's forces
//             could give (a collision) must leave at e times that speed; a
//             slower one (resting) must not approach; the impulse summed
//             over the passes stays at 0 or more. Each pass computes
//             the impulse of every contact once from the
//             velocities of the previous pass (Jacobi), each scaled by
//             1 / max(contacts of i, contacts of j): the same factor on
//             both sides, so momentum is conserved exactly and an isolated
//             pair gets its exact impulse (elastic: velocities swapped for
//             equal masses). A step with no resting contact (a gas) goes
//             on past the fixed passes until every collision meets its
//             target, so at e = 1 it keeps its energy (the impulses' work is
//             zero when each contact leaves at the speed it came in; a
//             step that reaches System::pairMaxPasses first returns a
//             warning, PairPassesWarning); a
//             pair overlapping at the start of the step bounces there only
//             when the step's forces changed neither velocity (free flight:
//             a collision the step before missed). After the passes a
//             particle's position moves by its velocity change times the
//             rest of the step after its first contact.
//   position  where the step's forces pull the resting particles one way
//             (a pile under gravity), the support sweep (SupportSweep):
//             Gauss-Seidel in order of height, a particle moved out of the
//             ones below it, which do not move, so a pile many layers deep
//             stands. Otherwise Jacobi passes: the remaining overlap along
//             each contact's normal is shared out by inverse mass, with
//             the same factor. Either way velocities are left alone (no
//             energy is created) and each particle is projected out of
//             the colliders again. A particle held by others (in resting
//             contact, or moved by the sweep) then takes the velocity of
//             its displacement over the step (position-based dynamics),
//             but no speed along the position work's move, so what the
//             passes leave unresolved does not build up in a pile; one
//             that barely moved is held still.
// Every sum runs in a fixed order and each particle is written by one
// thread (the sweeps, pipelined over the threads, write each particle in
// the serial sweeps' order): the result is bit-identical for any thread
// count.
//
// References: Mirtich, "Timewarp rigid body simulation" (swept spheres);
// Müller et al., "Position based dynamics" (2007), Jacobi projection;
// Guendelman, Bridson, Fedkiw, "Nonconvex rigid bodies with stacking"
// (2003), shock propagation.
#include "particles/pairs.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <thread>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "particles/def_check.h"
#include "particles/system.h"

namespace sylva::particles {

namespace {

constexpr int kVelocityPasses = 16;
// A step whose contacts are all collisions (no resting contact: a gas) is
// solved on past kVelocityPasses until every target speed is met within
// kConverged of the step's fastest approach, or System::pairMaxPasses.
constexpr double kConverged = 1e-12;
constexpr int kPositionPasses = 4;
// A held particle (in resting contact, or moved by the support sweep) that
// moved over the step at less than this fraction of the speed its forces
// alone gave it is held still: its velocity zeroed and, in a step with the
// sweep, its position kept (the velocity alone zeroed, the sweep's small
// corrections kept 1,678 of the 2,880-ball pile's balls creeping more than
// 1 cm a second after 5 s; at 0.75 and 0.5 the pile still churned after
// 5 s). Under 1: a ball that falls freely from rest moves at exactly that
// speed (at 1, rounding held some of the falling lattice's top balls in
// the air, a contact beside them).
constexpr double kRestFraction = 0.9;
// The support sweep runs where the resting particles' velocity changes by
// the step's forces, summed, are at least this fraction of the sum of
// their lengths (a common pull, as gravity; not a gas, not drag alone).
constexpr double kCommonPull = 0.5;
// The sweep (System::SupportSweep): a pair is a support where the higher
// centre is higher by kSupport of the radius sum (30 degrees above the
// horizontal); overlaps under kSlop of the radius sum are left; its pairs
// are those within kSweepMargin of the radius sum of touching; kSweeps
// sweeps a step (2 left twice the overlap of 4 in the 2,880-ball pile; 8
// took a fifth off the deepest at twice the cost).
constexpr double kSupport = 0.5;
constexpr double kSlop = 0.002;
constexpr double kSweepMargin = 0.5;
constexpr int kSweeps = 4;
// A pipelined sweep tells the one after it how far it has come every
// kSweepBlock turns.
constexpr size_t kSweepBlock = 32;
// Candidates of one particle gathered before their contacts are computed:
// the distance screen runs without a branch a candidate. The buffer's
// contacts are computed when fewer than kScreenRoom places are left (the
// order of the contacts does not depend on when).
constexpr uint32_t kCandidates = 64, kScreenRoom = 16;

// The first t in [0, 1] where |d0 + t dd| = R, or -1; 0 when |d0| < R.
double TimeOfImpact(const Vec3& d0, const Vec3& dd, double R) {
  const double c = d0.squaredNorm() - R * R;
  if (c < 0) return 0;
  const double b = d0.dot(dd);
  if (b >= 0) return -1;  // separating
  const double a = dd.squaredNorm();
  const double disc = b * b - a * c;
  if (disc < 0) return -1;
  const double t = c / (-b + std::sqrt(disc));  // the smaller root, stably
  return t <= 1 ? t : -1;
}

// max(x, 0) without a branch (a contact's impulse sign changes from pass to
// pass: a branch on it is mispredicted often). NaN gives 0, as std::max(0, x).
inline double PositivePart(double x) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(x), _mm_setzero_pd()));
#else
  return x > 0 ? x : 0;
#endif
}

// min(x, 0) without a branch; NaN gives 0.
inline double NegativePart(double x) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(x), _mm_setzero_pd()));
#else
  return x < 0 ? x : 0;
#endif
}

// v.resize(size), with room for a quarter more when it grows, so that a
// step whose contacts vary a little allocates nothing.
template <typename T>
void Grow(std::vector<T>& v, size_t size) {
  if (v.capacity() < size) v.reserve(size + size / 4);
  v.resize(size);
}

// A chunk's contacts as a pass reads them.
struct Contacts {
  const PairContact* __restrict ct;
  const uint32_t* __restrict q;
  double* __restrict impulse;
};

// A velocity pass's first half over the contacts of owners [pb, pe): each
// contact's impulse from the velocities vin, its push on the owner added
// to own[p], on the partner put in push[k] (push: the chunk's part of
// PairWork::out). With kGas, returns the
// largest residual of the bounce contacts (else 0).
template <bool kGas>
double VelocityOwners(size_t pb, size_t pe, const uint32_t* __restrict begin,
                      const uint32_t* __restrict end, const Contacts cs, const Vec3* __restrict vin,
                      Vec3* __restrict push, Vec3* __restrict own) {
  double worst = 0;
  for (size_t p = pb; p < pe; ++p) {
    Vec3 sum = Vec3::Zero();
    const Vec3 vp = vin[p];
    const uint32_t kb = begin[p], ke = end[p];
    for (uint32_t k = kb; k < ke; ++k) {
      const PairContact& ct = cs.ct[k];
      const double vn = ct.n.dot(vp - vin[cs.q[k]]);
      const double impulse = cs.impulse[k];
      // Off target: a pushing contact (impulse > 0) must meet its target
      // speed; one that does not push must not fall short.
      if constexpr (kGas)
        worst =
            std::max(worst, impulse > 0 ? std::abs(ct.target - vn) : std::max(0.0, ct.target - vn));
      // The impulse toward the target, its sum over the passes kept at 0
      // or more (contacts push, never pull).
      const double acc = PositivePart(impulse + (ct.target - vn) * ct.k);
      const Vec3 J = (acc - impulse) * ct.n;
      cs.impulse[k] = acc;
      sum += J;
      push[k] = J;
    }
    own[p] = sum;
  }
  return worst;
}

// Moves a particle of radius r at *x out of the colliders again (where a
// moving one ends the step) and takes the velocity *v into them away;
// returns how far it moved.
double OutOfColliders(const std::vector<Collider>& colliders, double h, double r, Vec3* x,
                      Vec3* v) {
  double moved = 0;
  for (const Collider& col : colliders) {
    const Vec3 shift = h * col.velocity;
    Vec3 sp, sn;
    if (col.Project(*x - shift, &sp, &sn, r)) {
      moved = std::max(moved, (sp + shift - *x).norm());
      *x = sp + shift;
      const double vn = (*v - col.velocity).dot(sn);
      if (vn < 0) *v -= vn * sn;
    }
  }
  return moved;
}

// Sorts a[0, n), in index order (a[p].second == p), as std::sort would
// sort the pairs (by height, equal heights by index): a least significant
// digit radix sort of the heights' bits, stable, so equal heights keep
// the order of their indices. tmp: room for n.
void SortByHeight(std::pair<double, uint32_t>* a, std::pair<double, uint32_t>* tmp, size_t n) {
  // The height's bits, ordered as the heights (-0 as 0, as they compare).
  auto key = [](double height) {
    if (height == 0) height = 0;
    uint64_t b;
    std::memcpy(&b, &height, sizeof b);
    return b >> 63 ? ~b : b | (uint64_t(1) << 63);
  };
  constexpr int kBits = 11, kDigits = (64 + kBits - 1) / kBits;
  constexpr uint32_t kBuckets = 1u << kBits;
  if (n < 2) return;
  uint32_t count[kDigits][kBuckets] = {};  // 48 KiB
  for (size_t i = 0; i < n; ++i) {
    const uint64_t k = key(a[i].first);
    for (int d = 0; d < kDigits; ++d) ++count[d][(k >> (d * kBits)) & (kBuckets - 1)];
  }
  std::pair<double, uint32_t>*from = a, *to = tmp;
  for (int d = 0; d < kDigits; ++d) {
    uint32_t* c = count[d];
    // A digit shared by every height moves nothing.
    if (c[(key(a[0].first) >> (d * kBits)) & (kBuckets - 1)] == n) continue;
    uint32_t sum = 0;
    for (uint32_t b = 0; b < kBuckets; ++b) sum += std::exchange(c[b], sum);
    for (size_t i = 0; i < n; ++i)
      to[c[(key(from[i].first) >> (d * kBits)) & (kBuckets - 1)]++] = from[i];
    std::swap(from, to);
  }
  if (from != a) std::copy(from, from + n, a);
}

// The screen reads positions as 3 doubles a particle.
static_assert(sizeof(Vec3) == 3 * sizeof(double));

// fn(begin, end) over ranges of [0, n), on the pool if there is one.
template <typename Fn>
void Ranges(ThreadPool* pool, size_t n, Fn&& fn) {
  if (!pool) {
    fn(size_t(0), n);
    return;
  }
  ForRanges(pool, n, BalancedGrain(pool, n, 256, 4096), fn);
}

// fn(c) for every chunk c < chunks, on the pool if there is one.
template <typename Fn>
void Chunks(ThreadPool* pool, size_t chunks, Fn&& fn) {
  if (!pool || chunks < 2) {
    for (size_t c = 0; c < chunks; ++c) fn(c);
    return;
  }
  pool->ParallelFor(chunks, fn);
}

}  // namespace

void System::ParticleCollisions(double h) {
  PairWork& pw = *pairWork_;
  pw.passes = 0;
  pw.gas = false;
  pw.converged = true;
  pw.residual = pw.tolerance = 0;
  const size_t n = state.size();
  if (n < 2) return;
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  const Vec3* X0 = pw.x0.data();
  const Vec3* V0 = pw.v0.data();
  auto radius = [&](size_t i) {
    return state.radius[i] > 0 ? double(state.radius[i]) : pairRadius_;
  };
  double maxR = 0, maxMove2 = 0;
  for (size_t i = 0; i < n; ++i) {
    maxR = std::max(maxR, radius(i));
    maxMove2 = std::max(maxMove2, (X[i] - X0[i]).squaredNorm());
  }
  const double maxMove = std::sqrt(maxMove2);
  if (!(maxMove <= 1e12)) return;  // an explosion: the fault scan reports it
  const double reach = 2 * maxR + 2 * maxMove;
  // With a copy of the start positions in slot order; from here every
  // array is in that order.
  pw.grid.Build(X0, n, reach, pool_, true);
  const uint32_t* order = pw.grid.order().data();
  const Vec3* x0 = pw.grid.sortedPositions().data();
  for (auto* a : {&pw.x, &pw.d, &pw.v, &pw.dv, &pw.scratch, &pw.own, &pw.xv}) a->resize(n);
  for (auto* a : {&pw.w, &pw.r, &pw.move, &pw.first}) a->resize(n);
  pw.begin.resize(n);
  pw.end.resize(n);
  pw.count.resize(n);
  pw.free.resize(n);
  pw.resting.resize(n);
  Vec3 *x = pw.x.data(), *d = pw.d.data(), *v = pw.v.data(), *dv = pw.dv.data();
  double *w = pw.w.data(), *r = pw.r.data(), *move = pw.move.data(), *first = pw.first.data();
  uint32_t *begin = pw.begin.data(), *end = pw.end.data();
  uint8_t *freeFlight = pw.free.data(), *resting = pw.resting.data();
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      const size_t i = order[p];
      x[p] = X[i];
      d[p] = X[i] - X0[i];
      v[p] = V[i];
      dv[p] = V[i] - V0[i];
      w[p] = state.invMass[i];
      r[p] = radius(i);
      move[p] = d[p].norm();
      freeFlight[p] = V[i] == V0[i];
    }
  });

  // Contacts, in one walk of the grid: each particle of a chunk looks
  // through half of its neighbourhood (so each pair is met once) and
  // appends the contacts it finds, which it owns, to the chunk's array.
  const size_t chunks = (n + kPairChunk - 1) / kPairChunk;
  if (pw.chunks.size() < chunks) pw.chunks.resize(chunks);
  const double r2 = reach * reach * (1 + 1e-9);
  Chunks(pool_, chunks, [&](size_t c) {
    PairChunk& ch = pw.chunks[c];
    ch.contacts.clear();
    ch.q.clear();
    ch.first.clear();
    ch.bounce.clear();
    ch.speed = 0;
    ch.resting = false;
    // Particle p's contacts among the candidates cand[0, m).
    auto contacts = [&](size_t p, const uint32_t* cand, uint32_t m) {
      const Vec3 xp = x0[p];
      for (uint32_t a = 0; a < m; ++a) {
        const uint32_t q = cand[a];
        if (w[p] + w[q] == 0) continue;
        const double R = r[p] + r[q];
        const Vec3 d0 = xp - x0[q];
        // Too far apart for their two steps to meet.
        const double meet = R + (move[p] + move[q]);
        if (d0.squaredNorm() > meet * meet) continue;
        const Vec3 dd = d[p] - d[q];
        const double t = TimeOfImpact(d0, dd, R);
        if (t < 0) continue;
        const Vec3 dc = d0 + t * dd;
        const double len = dc.norm();
        if (!(len > 0)) continue;  // coincident centres: no direction
        const Vec3 nrm = dc / len;
        const double vn0 = nrm.dot(v[p] - v[q]);
        // Speed the step's forces gave toward each other: a slower
        // approach is resting contact.
        const double gained = std::max(0.0, -nrm.dot(dv[p] - dv[q]));
        // A pair touching already at the start is in resting contact (what
        // a pile's passes leave of pushes and pops must not bounce), unless
        // the step's forces changed neither velocity: in free flight the
        // overlap is a collision the step before missed (a ball sent on by
        // one contact into another within that step), and it bounces.
        const bool bounce =
            (t > 0 || (freeFlight[p] && freeFlight[q])) && vn0 < -2 * gained - 1e-12;
        ch.contacts.push_back({nrm, bounce ? -pairRestitution_ * vn0 : 0.0, 0.0});
        ch.q.push_back(q);
        ch.first.push_back(t);
        ch.bounce.push_back(bounce);
        ch.speed = std::max(ch.speed, std::abs(vn0));
        resting[p] |= !bounce;
        first[p] = std::min(first[p], t);
      }
    };
    const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
    for (size_t p = pb; p < pe; ++p) {
      first[p] = 1;
      resting[p] = 0;
      begin[p] = uint32_t(ch.contacts.size());
      // The candidates: the grid's ranges, screened by distance without a
      // branch (kernels::ScreenCandidates), into a buffer of kCandidates,
      // whose contacts are computed when fewer than kScreenRoom are left.
      uint32_t from[14], to[14];
      int ranges = 0;
      pw.grid.ForEachHalfCandidateRange(x0[p], uint32_t(p), [&](uint32_t f, uint32_t t) {
        from[ranges] = f;
        to[ranges] = t;
        ++ranges;
      });
      // p's own reach: its radius and step with the largest of the others
      // (no pair that can meet is farther; the margin covers rounding).
      const double reachP = ((r[p] + maxR) + (move[p] + maxMove)) * (1 + 1e-9);
      const double reach2 = std::min(r2, reachP * reachP);
      uint32_t cand[kCandidates];
      uint32_t m = 0;
      for (int g = 0; g < ranges; ++g) {
        for (uint32_t f = from[g]; f < to[g];) {
          const uint32_t t = std::min(to[g], f + (kCandidates - m));
          m += kernels::ScreenCandidates(kernel_, x0[0].data(), f, t, x0[p].data(), reach2,
                                         cand + m);
          f = t;
          if (kCandidates - m < kScreenRoom) {
            contacts(p, cand, m);
            m = 0;
          }
        }
      }
      contacts(p, cand, m);
      end[p] = uint32_t(ch.contacts.size());
    }
    for (uint8_t b : ch.bounce) ch.resting |= !b;
    // Room for half as many again, so that a pile whose contacts vary a
    // little from step to step allocates nothing.
    const size_t m = ch.contacts.size();
    auto room = [m](auto& a) {
      if (a.capacity() < m + m / 4) a.reserve(m + m / 2);
    };
    room(ch.contacts);
    room(ch.q);
    room(ch.first);
    room(ch.bounce);
    room(ch.impulse);
    ch.impulse.assign(m, 0.0);
  });
  double speed = 0;
  bool anyResting = false;
  size_t total = 0;
  for (size_t c = 0; c < chunks; ++c) {
    PairChunk& ch = pw.chunks[c];
    speed = std::max(speed, ch.speed);
    anyResting |= ch.resting;
    SYLVA_ASSERT(total + ch.contacts.size() <= UINT32_MAX);  // places are 32-bit
    ch.base = uint32_t(total);
    total += ch.contacts.size();
  }
  if (total == 0) return;

  // The contacts of each partner: a counting sort of the contacts by
  // partner, in the chunks' order, so that a particle reads its pushes as
  // a partner from one list. It also brings the partner side's
  // first contact time and resting contact. count[p]: p's contacts, its own
  // and as partner. Serial (it reads 4 bytes a contact).
  Grow(pw.partnerBegin, n + 2);
  Grow(pw.pushFrom, total);
  Grow(pw.out, total);
  uint32_t* partnerBegin = pw.partnerBegin.data();
  uint32_t* count = pw.count.data();
  std::fill(partnerBegin, partnerBegin + n + 2, 0u);
  for (size_t c = 0; c < chunks; ++c) {
    for (uint32_t q : pw.chunks[c].q) ++partnerBegin[q + 2];
  }
  for (size_t p = 0; p < n; ++p) {
    count[p] = end[p] - begin[p] + partnerBegin[p + 2];
    partnerBegin[p + 2] += partnerBegin[p + 1];
  }
  for (size_t c = 0; c < chunks; ++c) {
    PairChunk& ch = pw.chunks[c];
    const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
    for (size_t p = pb; p < pe; ++p) {
      for (uint32_t e = begin[p]; e < end[p]; ++e) {
        const uint32_t q = ch.q[e];
        pw.pushFrom[partnerBegin[q + 1]++] = ch.base + e;
        first[q] = std::min(first[q], ch.first[e]);
        resting[q] |= !ch.bounce[e];
      }
    }
  }
  Vec3* out = pw.out.data();
  Vec3* own = pw.own.data();
  const uint32_t* pushFrom = pw.pushFrom.data();
  // The passes' parts: the chunks [partBegin[i], partBegin[i + 1]), of
  // about equal work (particles and their contacts), one for each of the
  // pool's threads, which takes it in every pass (ThreadPool::
  // ForEachPart): what a part writes in a pass, it reads in the next from
  // its own core's cache. (Handed to either thread, the velocity passes'
  // arrays moved between the cores every pass: two threads took as long
  // as one.)
  const size_t parts = pool_ ? std::min<size_t>(size_t(pool_->threads()), chunks) : 1;
  Grow(pw.partBegin, parts + 1);
  size_t* partBegin = pw.partBegin.data();
  {
    size_t work = 0;
    for (size_t p = 0; p < n; ++p) work += 1 + count[p];
    size_t done = 0, part = 1;
    partBegin[0] = 0;
    for (size_t c = 0; c < chunks && part < parts; ++c) {
      for (size_t p = c * kPairChunk; p < std::min(n, (c + 1) * kPairChunk); ++p)
        done += 1 + count[p];
      while (part < parts && done * parts >= work * part) partBegin[part++] = c + 1;
    }
    while (part <= parts) partBegin[part++] = chunks;
  }
  auto passChunks = [&](auto&& fn) {
    if (parts < 2) {
      for (size_t c = 0; c < chunks; ++c) fn(c);
      return;
    }
    pool_->ForEachPart(parts, [&](size_t i) {
      for (size_t c = partBegin[i]; c < partBegin[i + 1]; ++c) fn(c);
    });
  };

  // Velocity passes (Jacobi), kVelocityPasses; where no contact of the
  // step is resting, on while a collision contact is off its target by more
  // than kConverged of the step's largest approach speed, up to
  // pairMaxPasses (a pile keeps its fixed passes: converging them costs 15x
  // and does not settle it). A pass computes each contact's impulse once,
  // by its owner, from the velocities of the pass before, and keeps the
  // owner's sum and puts each contact's push on its partner in the
  // partner's run; then each particle takes its own sum less the pushes of
  // its run. Each
  // chunk records the largest residual of its bounce contacts; their
  // maximum is the same whatever the thread count (a max does not depend
  // on the order). The first pass also computes each contact's sharing
  // factor.
  pw.gas = !anyResting;
  pw.tolerance = kConverged * speed;
  passChunks([&](size_t c) {
    PairChunk& ch = pw.chunks[c];
    const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
    for (size_t p = pb; p < pe; ++p) {
      for (uint32_t k = begin[p]; k < end[p]; ++k) {
        const uint32_t q = ch.q[k];
        const double f = 1.0 / double(std::max(count[p], count[q]));
        ch.contacts[k].k = f / (w[p] + w[q]);
      }
    }
  });
  const bool gas = pw.gas;
  const int passes = gas ? std::max(pairMaxPasses, kVelocityPasses) : kVelocityPasses;
  for (int pass = 0; pass < passes; ++pass) {
    const Vec3* vin = pw.v.data();
    Vec3* vout = pw.scratch.data();
    passChunks([&](size_t c) {
      PairChunk& ch = pw.chunks[c];
      const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
      const Contacts cs{ch.contacts.data(), ch.q.data(), ch.impulse.data()};
      Vec3* const push = out + ch.base;
      ch.residual = gas ? VelocityOwners<true>(pb, pe, begin, end, cs, vin, push, own)
                        : VelocityOwners<false>(pb, pe, begin, end, cs, vin, push, own);
    });
    passChunks([&](size_t c) {
      const Vec3 *const push = out, *const ownSum = own, *const vi = vin;
      const uint32_t *const run = partnerBegin, *const from = pushFrom;
      Vec3* const vo = vout;
      const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
      for (size_t p = pb; p < pe; ++p) {
        Vec3 sum = ownSum[p];
        for (uint32_t k = run[p]; k < run[p + 1]; ++k) sum -= push[from[k]];
        vo[p] = vi[p] + w[p] * sum;
      }
    });
    // The residuals were those of the velocities before this pass: met,
    // the pass changed nothing that matters; keep its result all the same.
    std::swap(pw.v, pw.scratch);
    v = pw.v.data();
    pw.passes = pass + 1;
    if (gas && pass + 1 >= kVelocityPasses) {
      double worst = 0;
      for (size_t c = 0; c < chunks; ++c) worst = std::max(worst, pw.chunks[c].residual);
      pw.residual = worst;
      if (worst <= pw.tolerance) break;
    }
  }
  pw.converged = !pw.gas || pw.residual <= pw.tolerance;
  // Positions follow the new velocities over the rest of the step after
  // the first contact.
  Ranges(pool_, n, [&](size_t b, size_t e2) {
    for (size_t p = b; p < e2; ++p) {
      if (count[p] == 0 || w[p] == 0) continue;
      const size_t i = order[p];
      x[p] += ((1 - first[p]) * h) * (v[p] - V[i]);
    }
  });

  // Where the step's forces pull the resting particles one way (gravity),
  // the support sweep below holds the pile up; it runs after the position
  // passes.
  Vec3 pull = Vec3::Zero();
  double pullSum = 0;
  if (anyResting) {
    for (size_t p = 0; p < n; ++p) {
      if (!resting[p] || w[p] == 0) continue;
      pull += dv[p];
      pullSum += dv[p].norm();
    }
  }
  const bool sweep = pullSum > 0 && pull.norm() > kCommonPull * pullSum;
  // The positions the velocities gave: what the position work moves a
  // particle from (its velocity gains nothing from that move).
  Vec3* xv = pw.xv.data();
  std::copy(x, x + n, xv);

  // Position passes (Jacobi): the remaining overlap along each normal, in
  // the same two halves as a velocity pass.
  // (A step with the sweep leaves the overlaps to it: with the passes
  // before it the 10,000 balls settled no better and took a tenth longer.)
  const int positionPasses = sweep ? 0 : kPositionPasses;
  for (int pass = 0; pass < positionPasses; ++pass) {
    const Vec3* xin = pw.x.data();
    Vec3* xout = pw.scratch.data();
    passChunks([&](size_t c) {
      const PairChunk& ch = pw.chunks[c];
      const PairContact* const cs = ch.contacts.data();
      const uint32_t* const cq = ch.q.data();
      const uint32_t *const b = begin, *const e = end;
      const Vec3* const xi = xin;
      const double* const rad = r;
      Vec3 *const push = out + ch.base, *const ownSum = own;
      const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
      for (size_t p = pb; p < pe; ++p) {
        Vec3 sum = Vec3::Zero();
        const Vec3 xp = xi[p];
        for (uint32_t k = b[p]; k < e[p]; ++k) {
          const PairContact& ct = cs[k];
          const uint32_t q = cq[k];
          const double gap = ct.n.dot(xp - xi[q]) - (rad[p] + rad[q]);
          const Vec3 s = (NegativePart(gap) * ct.k) * ct.n;
          sum += s;
          push[k] = s;
        }
        ownSum[p] = sum;
      }
    });
    passChunks([&](size_t c) {
      const size_t pb = c * kPairChunk, pe = std::min(n, pb + kPairChunk);
      for (size_t p = pb; p < pe; ++p) {
        if (w[p] == 0 || count[p] == 0) {
          xout[p] = xin[p];
          continue;
        }
        Vec3 sum = own[p];
        for (uint32_t k = partnerBegin[p]; k < partnerBegin[p + 1]; ++k) sum -= out[pushFrom[k]];
        Vec3 xp = xin[p] - w[p] * sum;
        OutOfColliders(colliders_, h, r[p], &xp, &v[p]);
        xout[p] = xp;
      }
    });
    // Every particle read the positions of the pass before.
    std::swap(pw.x, pw.scratch);
    x = pw.x.data();
  }

  if (sweep) SupportSweep(-pull.normalized(), h);
  x = pw.x.data();

  // A particle held by others (in resting contact, or moved by the sweep)
  // takes the velocity of its displacement over the step (position-based
  // dynamics), so that what the passes leave of the forces' push into its
  // neighbours does not build up from step to step and a pile comes to
  // rest; but the position work (the position passes and the sweep) only
  // stops an approach: it gives no speed along its move beyond what the
  // velocities had (a ball squeezed out between others would leave at the
  // squeeze over the step). At rest: a held particle that moved over the
  // step at less than kRestFraction of the speed its forces alone gave it
  // in the step is held still: its velocity is zeroed and, after a sweep,
  // it stays where it was, so what the passes leave of the forces' push
  // does not make a pile jitter or creep. Then the particles take their
  // new state (the sweep may move one with no contact).
  Ranges(pool_, n, [&](size_t b, size_t e2) {
    for (size_t p = b; p < e2; ++p) {
      if (w[p] == 0) continue;
      const size_t i = order[p];
      Vec3 vp = v[p];
      const Vec3 moved = x[p] - xv[p];
      if (resting[p] || (sweep && pw.swept[p] != Vec3::Zero())) {
        vp = (x[p] - x0[p]) * (1 / h);
        if (moved != Vec3::Zero()) {
          const double len = moved.norm();
          const Vec3 c = moved / len;
          const double along = c.dot(vp);
          const double cap = std::max(along - len / h, 0.0);
          if (along > cap) vp -= (along - cap) * c;
        }
        if (vp.norm() < kRestFraction * dv[p].norm()) {
          vp = Vec3::Zero();
          if (sweep && (x[p] - x0[p]).norm() < kRestFraction * h * dv[p].norm()) x[p] = x0[p];
        }
      }
      X[i] = x[p];
      V[i] = vp;
    }
  });
}

// The support sweep (shock propagation: Guendelman, Bridson and Fedkiw,
// "Nonconvex rigid bodies with stacking", SIGGRAPH 2003, section 7). The
// Jacobi passes move a correction one contact a pass, so a pile many
// layers deep sank into itself (10,000 balls in a box 2 m wide: 43 % of a
// radius of overlap on average, some centres on top of one another, the
// pile a sixth of its height). The sweep takes the particles in order of
// height along `up` (against the step's common pull) and resolves each
// one's overlaps with the particles before it in that order, Gauss-Seidel:
//   support  a particle below p, p's centre higher by kSupport of their
//            radius sum or more, does not move: p moves out of it along
//            their normal (the floor's support reaches the top of a
//            pile in one sweep);
//   beside   nearer the horizontal, both move, by inverse mass, and the
//            higher one only sideways (lifted, a ball squeezed between
//            another and a wall climbed it a few millimetres a step).
// Overlaps under kSlop of the radius sum are left (correcting every last
// one kept the surface of a pile stirring). Then p is moved out of the
// colliders. The pairs are those within kSweepMargin of touching after the
// position passes, from a grid of their own over those positions, its
// cells as small as the pairs' reach (the contacts found above miss balls
// that move as one: a column falling together has none between its
// balls), gathered once, in parallel, each particle's in order of height;
// kSweeps sweeps, pipelined over the threads with the serial sweeps'
// result (below). A swept particle's own move is in
// PairWork::swept. All in an order that does not depend on the thread
// count.
void System::SupportSweep(const Vec3& up, double h) {
  PairWork& pw = *pairWork_;
  const size_t n = pw.x.size();
  Vec3* x = pw.x.data();
  Vec3* v = pw.v.data();
  const double* w = pw.w.data();
  const double* r = pw.r.data();
  Grow(pw.byHeight, n);
  Grow(pw.swept, n);
  auto* byHeight = pw.byHeight.data();
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) byHeight[p] = {up.dot(x[p]), uint32_t(p)};
  });
  Grow(pw.byHeightScratch, n);
  SortByHeight(byHeight, pw.byHeightScratch.data(), n);
  // The sweeps work in order of height (the particles they read together
  // are near in memory): positions, inverse masses and radii copied so.
  Grow(pw.xh, n);
  Grow(pw.wh, n);
  Grow(pw.rh, n);
  Vec3* xh = pw.xh.data();
  double *wh = pw.wh.data(), *rh = pw.rh.data();
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const uint32_t p = byHeight[k].second;
      xh[k] = x[p];
      wh[k] = w[p];
      rh[k] = r[p];
    }
  });
  // Each particle's pairs with those before it, in order of height (their
  // places in it): the k-th particle's are near[nearBegin[k], nearBegin[k +
  // 1]). Each pair is found once, from the half neighbourhood of one of its
  // particles in a grid over the positions in order of height, in
  // parallel, a chunk of the grid's slots at a time, and goes to the list
  // of its higher particle; each list is then sorted, so the lists do not
  // depend on the grid's layout or on the thread count.
  const size_t chunks = (n + kPairChunk - 1) / kPairChunk;
  if (pw.nearChunks.size() < chunks) pw.nearChunks.resize(chunks);
  Grow(pw.nearBegin, n + 1);
  Grow(pw.nearEnd, n);
  uint32_t* nearBegin = pw.nearBegin.data();
  uint32_t* nearEnd = pw.nearEnd.data();  // counts, then cursors, then ends
  std::fill(nearEnd, nearEnd + n, 0u);
  double maxR = 0;
  for (size_t p = 0; p < n; ++p) maxR = std::max(maxR, r[p]);
  const double screen = 2 * maxR * (1 + kSweepMargin);
  // A candidate's slot s in the grid is the particle of place
  // sweepOrder[s], at sweepX[s].
  pw.sweepGrid.Build(xh, n, screen, pool_, true);
  const uint32_t* sweepOrder = pw.sweepGrid.order().data();
  const Vec3* sweepX = pw.sweepGrid.sortedPositions().data();
  Chunks(pool_, chunks, [&](size_t c) {
    std::vector<uint32_t>& pairs = pw.nearChunks[c];  // (higher, lower) places
    pairs.clear();
    uint32_t cand[kCandidates];
    for (size_t s = c * kPairChunk; s < std::min(n, (c + 1) * kPairChunk); ++s) {
      const uint32_t a = sweepOrder[s];
      const Vec3 xa = sweepX[s];
      // The grid's candidates screened by distance (kernels::
      // ScreenCandidates), then by each pair's own reach.
      pw.sweepGrid.ForEachHalfCandidateRange(xa, uint32_t(s), [&](uint32_t f, uint32_t t) {
        for (uint32_t from = f; from < t;) {
          const uint32_t to = std::min(t, from + kCandidates);
          const uint32_t m = kernels::ScreenCandidates(kernel_, sweepX[0].data(), from, to,
                                                       xa.data(), screen * screen, cand);
          for (uint32_t i = 0; i < m; ++i) {
            const uint32_t b = sweepOrder[cand[i]];
            if (wh[a] + wh[b] == 0) continue;
            const double near = (rh[a] + rh[b]) * (1 + kSweepMargin);
            if ((xa - sweepX[cand[i]]).squaredNorm() >= near * near) continue;
            const uint32_t higher = std::max(a, b);
            pairs.push_back(higher);
            pairs.push_back(std::min(a, b));
          }
          from = to;
        }
      });
    }
  });
  // Filed serially (atomic counts from both threads fought over the
  // counters' cache lines: the gathering scaled 1.4x on two threads). For
  // the pipelined sweeps (below), the same loop finds the last turn that
  // touches each place: reach[j], the highest place whose list holds j
  // (or j).
  const bool pipelined = pool_ && pool_->threads() >= 2 && n >= 2 * kSweepBlock;
  uint32_t* reach = nullptr;
  if (pipelined) {
    Grow(pw.sweepReach, n);
    reach = pw.sweepReach.data();
    for (size_t k = 0; k < n; ++k) reach[k] = uint32_t(k);
  }
  size_t total = 0;
  for (size_t c = 0; c < chunks; ++c) total += pw.nearChunks[c].size() / 2;
  SYLVA_ASSERT(total <= UINT32_MAX);  // the lists' places are 32-bit
  for (size_t c = 0; c < chunks; ++c) {
    const std::vector<uint32_t>& pairs = pw.nearChunks[c];
    for (size_t i = 0; i < pairs.size(); i += 2) {
      ++nearEnd[pairs[i]];
      if (reach) reach[pairs[i + 1]] = std::max(reach[pairs[i + 1]], pairs[i]);
    }
  }
  nearBegin[0] = 0;
  for (size_t k = 0; k < n; ++k) {
    nearBegin[k + 1] = nearBegin[k] + nearEnd[k];
    nearEnd[k] = nearBegin[k];
  }
  Grow(pw.near, nearBegin[n]);
  uint32_t* nearList = pw.near.data();
  for (size_t c = 0; c < chunks; ++c) {
    const std::vector<uint32_t>& pairs = pw.nearChunks[c];
    for (size_t i = 0; i < pairs.size(); i += 2) nearList[nearEnd[pairs[i]]++] = pairs[i + 1];
  }
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) std::sort(nearList + nearBegin[k], nearList + nearBegin[k + 1]);
  });
  Vec3* swept = pw.swept.data();
  std::copy(x, x + n, swept);
  // The k-th particle's turn in a sweep: its overlaps with those before it
  // resolved. Reads and writes the places k and its list's, and v of k.
  auto turn = [&](size_t k) {
    Vec3 xp = xh[k];
    bool moved = false;
    for (uint32_t a = nearBegin[k]; a < nearBegin[k + 1]; ++a) {
      const uint32_t j = nearList[a];
      const Vec3 dq = xp - xh[j];
      const double R = rh[k] + rh[j], Rs = R * (1 - kSlop);
      const double d2 = dq.squaredNorm();
      if (d2 >= Rs * Rs) continue;
      const double len = std::sqrt(d2);
      // Coincident centres: p goes up.
      const Vec3 nrm = len > 0 ? Vec3(dq / len) : up;
      const double lift = len > 0 ? up.dot(nrm) : 1.0;
      const double depth = Rs - len;
      moved = true;
      if (lift >= kSupport || wh[j] == 0) {
        xp += depth * nrm;
      } else if (lift <= -kSupport || wh[k] == 0) {
        xh[j] -= depth * nrm;  // q has come to lie on p
      } else {
        const double share = wh[k] / (wh[k] + wh[j]);
        const Vec3 side = nrm - lift * up;  // |side| >= cos(asin(kSupport))
        const Vec3 sideways = side / side.squaredNorm();
        xp += (share * depth) * (lift >= 0 ? sideways : nrm);
        xh[j] -= ((1 - share) * depth) * (lift >= 0 ? nrm : sideways);
      }
    }
    if (!moved) return false;
    if (wh[k] != 0) OutOfColliders(colliders_, h, rh[k], &xp, &v[byHeight[k].second]);
    xh[k] = xp;
    return true;
  };
  if (!pipelined) {
    for (int pass = 0; pass < kSweeps; ++pass) {
      bool changed = false;
      for (size_t k = 0; k < n; ++k) changed |= turn(k);
      if (!changed) break;  // nothing left to resolve
    }
  } else {
    // The sweeps as a pipeline, one thread a sweep, each a little behind
    // the one before: the k-th turn of a sweep waits until the sweep
    // before has taken every turn that touches a place the k-th turn
    // touches (up to wait[k]), so every place sees the same operations in
    // the same order as in the serial sweeps: the same bits. A sweep that
    // changed nothing ends the ones after it (the serial sweeps stop
    // there; the later ones, on the same positions, change nothing
    // either).
    // reach (filed above): the last turn that touches each place;
    // wait[k]: the last turn that touches a place the k-th touches.
    Grow(pw.sweepWait, n);
    uint32_t* wait = pw.sweepWait.data();
    Ranges(pool_, n, [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        uint32_t m = reach[k];
        for (uint32_t a = nearBegin[k]; a < nearBegin[k + 1]; ++a)
          m = std::max(m, reach[nearList[a]]);
        wait[k] = m;
      }
    });
    std::atomic<size_t> done[kSweeps];
    for (auto& d : done) d.store(0, std::memory_order_relaxed);
    std::atomic<bool> still{false};  // a sweep has changed nothing
    pool_->ParallelFor(kSweeps, [&](size_t pass) {
      bool changed = false;
      size_t ready = pass == 0 ? n : 0;  // turns known taken by the sweep before
      for (size_t k = 0; k < n; ++k) {
        for (int spins = 0; ready <= wait[k]; ++spins) {
          ready = done[pass - 1].load(std::memory_order_acquire);
          if (ready > wait[k]) break;
          if (still.load(std::memory_order_acquire)) {
            // Every turn so far changed nothing; none after will.
            done[pass].store(n, std::memory_order_release);
            return;
          }
          if (spins > 64) std::this_thread::yield();
        }
        changed |= turn(k);
        if ((k + 1) % kSweepBlock == 0) done[pass].store(k + 1, std::memory_order_release);
      }
      if (!changed) still.store(true, std::memory_order_release);
      done[pass].store(n, std::memory_order_release);
    });
  }
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) x[byHeight[k].second] = xh[k];
  });
  // Every particle out of the colliders (one moved after its turn, beside
  // a higher one, or by the velocities after its first contact, may be in
  // one).
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      if (w[p] != 0) OutOfColliders(colliders_, h, r[p], &x[p], &v[p]);
      swept[p] = x[p] - swept[p];
    }
  });
}

Status System::PairPassesWarning(const char* what) const {
  const PairWork& pw = *pairWork_;
  Diagnostic d = MakeError(
      {}, "particles: " + std::string(what) + " step " + std::to_string(state.step) +
              " (from t = " + check::Num(state.time) +
              " s): the particle collisions did not converge in " + std::to_string(pw.passes) +
              " velocity passes (System.pairMaxPasses): a collision is still " +
              check::Num(pw.residual) + " m/s off its target speed (tolerance " +
              check::Num(pw.tolerance) +
              " m/s); the step kept what the passes gave, so an elastic gas does not keep its "
              "energy exactly; raise pairMaxPasses or take smaller steps");
  d.severity = Severity::kWarning;
  d.kind = ErrorKind::kRuntime;
  return d;
}

}  // namespace sylva::particles
