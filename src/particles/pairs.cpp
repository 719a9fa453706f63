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
// of impact and the relative normal speed before the solve.
//
// Response, in two kinds of passes over each particle's own list of
// contacts (CSR, in the grid's order: the same whatever the thread count):
//   velocity  a contact whose approach is faster than the step's forces
//             could give (a collision) must leave at e times that speed; a
//             slower one (resting) must not approach; the impulse summed
//             over the passes stays at 0 or more. Each pass computes,
//             for every particle, the impulses of its contacts from the
//             velocities of the previous pass (Jacobi), each scaled by
//             1 / max(contacts of i, contacts of j): the same factor on
//             both sides, so momentum is conserved exactly and an isolated
//             pair gets its exact impulse (elastic: velocities swapped for
//             equal masses). A step with no resting contact (a gas) goes
//             on past the fixed passes until every collision meets its
//             target, so at e = 1 it keeps its energy (the impulses' work is
//             zero when each contact leaves at the speed it came in); a
//             pair overlapping at the start of the step bounces there only
//             when the step's forces changed neither velocity (free flight:
//             a collision the step before missed). After the passes a
//             particle's position moves by its velocity change times the
//             rest of the step after its first contact.
//   position  the remaining overlap along each contact's normal is shared
//             out by inverse mass, with the same factor; velocities are
//             left alone (no energy is created). Then each particle is
//             projected out of the half-space colliders again. A particle
//             in resting contact then takes the velocity of its
//             displacement over the step (position-based dynamics), so what
//             the passes leave unresolved does not build up in a pile.
// Every sum runs in a fixed order and each particle is written by one
// thread: the result is bit-identical for any thread count.
//
// References: Mirtich, "Timewarp rigid body simulation" (swept spheres);
// Müller et al., "Position based dynamics" (2007), Jacobi projection.
#include <algorithm>
#include <cmath>

#include "particles/grid.h"
#include "particles/system.h"

namespace sylva::particles {

namespace {

constexpr int kVelocityPasses = 16;
// A step whose contacts are all collisions (no resting contact: a gas) is
// solved on past kVelocityPasses until every target speed is met within
// kConverged of the step's fastest approach, or this many passes.
constexpr int kMaxVelocityPasses = 1024;
constexpr double kConverged = 1e-12;
constexpr int kPositionPasses = 4;
constexpr double kRestFraction = 0.5;

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

// fn(begin, end) over ranges of [0, n), on the pool if there is one.
template <typename Fn>
void Ranges(ThreadPool* pool, size_t n, Fn&& fn) {
  if (!pool) {
    fn(size_t(0), n);
    return;
  }
  ForRanges(pool, n, BalancedGrain(pool, n, 256, 4096), fn);
}

}  // namespace

void System::ParticleCollisions(double h) {
  const size_t n = state.size();
  if (n < 2) return;
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  const Vec3* X0 = pairX0_.data();
  const Vec3* V0 = pairV0_.data();
  const double* w = state.invMass.data();
  auto radius = [&](size_t i) {
    return state.radius[i] > 0 ? double(state.radius[i]) : pairRadius_;
  };
  double maxR = 0, maxMove = 0;
  pairMove_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    maxR = std::max(maxR, radius(i));
    pairMove_[i] = (X[i] - X0[i]).norm();
    maxMove = std::max(maxMove, pairMove_[i]);
  }
  if (!(maxMove <= 1e12)) return;  // an explosion: the fault scan reports it
  const double reach = 2 * maxR + 2 * maxMove;
  // With a copy of the start positions in slot order: every particle
  // queries, and reads its candidates contiguously.
  pairGrid_->Build(X0, n, reach, pool_, true);

  // Contacts, particle by particle: count, offsets, fill.
  auto find = [&](size_t i, auto&& emit) {
    pairGrid_->ForEachNeighbour(X0, i, reach, [&](size_t j) {
      if (w[i] + w[j] == 0) return;
      const double R = radius(i) + radius(j);
      const Vec3 d0 = X0[i] - X0[j];
      // Too far apart for their two steps to meet.
      const double meet = R + pairMove_[i] + pairMove_[j];
      if (d0.squaredNorm() > meet * meet) return;
      const Vec3 dd = (X[i] - X0[i]) - (X[j] - X0[j]);
      const double t = TimeOfImpact(d0, dd, R);
      if (t < 0) return;
      const Vec3 d = d0 + t * dd;
      const double len = d.norm();
      if (!(len > 0)) return;  // coincident centres: no direction
      emit(j, t, Vec3(d / len), R);
    });
  };
  pairStart_.assign(n + 1, 0);
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      uint32_t c = 0;
      find(i, [&](size_t, double, const Vec3&, double) { ++c; });
      pairStart_[i + 1] = c;
    }
  });
  for (size_t i = 0; i < n; ++i) pairStart_[i + 1] += pairStart_[i];
  const size_t total = pairStart_[n];
  if (total == 0) return;
  pairs_.resize(total);
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      size_t k = pairStart_[i];
      find(i, [&](size_t j, double t, const Vec3& nrm, double R) {
        PairContact& c = pairs_[k++];
        c.j = uint32_t(j);
        c.t = t;
        c.n = nrm;
        c.R = R;
        c.vn0 = nrm.dot(V[i] - V[j]);
        // Speed the step's forces gave toward each other: a slower approach
        // is resting contact.
        const double gained = std::max(0.0, -nrm.dot((V[i] - V0[i]) - (V[j] - V0[j])));
        // A pair touching already at the start is in resting contact (what
        // a pile's passes leave of pushes and pops must not bounce), unless
        // the step's forces changed neither velocity: in free flight the
        // overlap is a collision the step before missed (a ball sent on by
        // one contact into another within that step), and it bounces.
        const bool free = V[i] == V0[i] && V[j] == V0[j];
        c.bounce = (t > 0 || free) && c.vn0 < -2 * gained - 1e-12;
        c.impulse = 0;
      });
    }
  });
  auto factor = [&](size_t i, uint32_t j) {
    const uint32_t ci = pairStart_[i + 1] - pairStart_[i];
    const uint32_t cj = pairStart_[j + 1] - pairStart_[j];
    return 1.0 / double(std::max(ci, cj));
  };

  // Each contact's target speed and sharing factor, once.
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      for (uint32_t k = pairStart_[i]; k < pairStart_[i + 1]; ++k) {
        PairContact& c = pairs_[k];
        c.target = c.bounce ? -pairRestitution_ * c.vn0 : 0;
        c.k = w[i] > 0 ? factor(i, c.j) / (w[i] + w[c.j]) : 0;
      }
    }
  });

  // From here pairMove_ holds what the step's forces changed each
  // velocity by (|v - v0| before the solve), for the rest test at the end.
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) pairMove_[i] = (V[i] - V0[i]).norm();
  });

  // Velocity passes (Jacobi), kVelocityPasses; where no contact of the
  // step is resting, on while a collision contact is off its target by more
  // than kConverged of the step's largest approach speed, up to
  // kMaxVelocityPasses (a pile keeps its fixed passes: converging them
  // costs 15x and does not settle it). Each
  // particle records the largest residual of its bounce contacts; their
  // maximum is the same whatever the thread count (a max does not depend
  // on the order).
  pairV_.assign(V.begin(), V.end());
  pairScratch_.resize(n);
  pairResidual_.resize(n);
  double speed = 0;
  bool resting = false;
  for (size_t k = 0; k < total; ++k) {
    speed = std::max(speed, std::abs(pairs_[k].vn0));
    resting |= !pairs_[k].bounce;
  }
  const double tolerance = kConverged * speed;
  const int passes = resting ? kVelocityPasses : kMaxVelocityPasses;
  for (int pass = 0; pass < passes; ++pass) {
    Ranges(pool_, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        Vec3 dv = Vec3::Zero();
        double residual = 0;
        if (w[i] > 0) {
          for (uint32_t k = pairStart_[i]; k < pairStart_[i + 1]; ++k) {
            PairContact& c = pairs_[k];
            const double vn = c.n.dot(pairV_[i] - pairV_[c.j]);
            // Off target: a pushing contact (impulse > 0) must meet its
            // target speed; one that does not push must not fall short.
            if (c.bounce)
              residual = std::max(
                  residual, c.impulse > 0 ? std::abs(c.target - vn) : std::max(0.0, c.target - vn));
            // The impulse toward the target, its sum over the passes kept
            // at 0 or more (contacts push, never pull). Both particles of a
            // pair compute the same numbers.
            const double acc = std::max(0.0, c.impulse + (c.target - vn) * c.k);
            const double J = acc - c.impulse;
            c.impulse = acc;
            dv += (J * w[i]) * c.n;
          }
        }
        pairResidual_[i] = residual;
        pairScratch_[i] = pairV_[i] + dv;
      }
    });
    // The residuals were those of the velocities before this pass: met,
    // the pass changed nothing that matters; keep its result all the same.
    std::swap(pairV_, pairScratch_);
    if (pass + 1 >= kVelocityPasses) {
      double worst = 0;
      for (size_t i = 0; i < n; ++i) worst = std::max(worst, pairResidual_[i]);
      if (worst <= tolerance) break;
    }
  }
  // New velocities; positions follow them over the rest of the step after
  // the first contact.
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (pairStart_[i + 1] == pairStart_[i] || w[i] == 0) continue;
      double first = 1;
      for (uint32_t k = pairStart_[i]; k < pairStart_[i + 1]; ++k)
        first = std::min(first, pairs_[k].t);
      X[i] += ((1 - first) * h) * (pairV_[i] - V[i]);
      V[i] = pairV_[i];
    }
  });

  // Position passes (Jacobi): the remaining overlap along each normal.
  const double rh = h;
  for (int pass = 0; pass < kPositionPasses; ++pass) {
    Ranges(pool_, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        Vec3 dx = Vec3::Zero();
        if (w[i] > 0) {
          for (uint32_t k = pairStart_[i]; k < pairStart_[i + 1]; ++k) {
            const PairContact& c = pairs_[k];
            const double gap = c.n.dot(X[i] - X[c.j]) - c.R;
            if (gap >= 0) continue;
            dx -= (gap * w[i] / (w[i] + w[c.j]) * factor(i, c.j)) * c.n;
          }
        }
        Vec3 x = X[i] + dx;
        Vec3 v = V[i];
        if (w[i] > 0 && pairStart_[i + 1] > pairStart_[i]) {
          // Out of the half-space colliders again (where a moving one ends
          // the step), without velocity into them.
          for (const Collider& col : colliders_) {
            const Vec3 shift = rh * col.velocity;
            Vec3 sp, sn;
            if (col.Project(x - shift, &sp, &sn, radius(i))) {
              x = sp + shift;
              const double vn = (v - col.velocity).dot(sn);
              if (vn < 0) v -= vn * sn;
            }
          }
        }
        pairScratch_[i] = x;
        pairV_[i] = v;
      }
    });
    // Every particle read X of the pass before; now the new positions.
    Ranges(pool_, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        X[i] = pairScratch_[i];
        V[i] = pairV_[i];
      }
    });
  }
  // A particle in resting contact takes the velocity of its displacement
  // over the step (position-based dynamics): what the passes left of the
  // forces' push into its neighbours does not build up from step to step,
  // and a pile comes to rest.
  Ranges(pool_, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (w[i] == 0) continue;
      bool resting = false;
      for (uint32_t k = pairStart_[i]; k < pairStart_[i + 1]; ++k) resting |= !pairs_[k].bounce;
      if (!resting) continue;
      V[i] = (X[i] - X0[i]) * (1 / h);
      // At rest: a particle in resting contact that moved over the step at
      // less than half the speed its forces alone gave it in the step is
      // held by its neighbours; its velocity is zeroed, so what the passes
      // leave of the forces' push does not make a pile jitter.
      if (V[i].norm() < kRestFraction * pairMove_[i]) V[i] = Vec3::Zero();
    }
  });
}

}  // namespace sylva::particles
