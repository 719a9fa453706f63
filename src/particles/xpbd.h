// XPBD distance-constraint projection kernels (Macklin, Muller & Chentanez,
// "XPBD: Position-based simulation of compliant constrained dynamics",
// MIG 2016), internal to the particles library.
//
// On padded positions with an AVX kernel and its scalar twin (kernels.h):
// the projection kernel takes four constraints of a colour (which share no
// particle) at a time, the particle pass four particles.
#pragma once

#include <cstddef>
#include <cstdint>

#include "particles/kernels.h"

namespace sylva::particles::xpbd {

// One constraint, set once a frame: the ends, the rest length,
// scale = 1 / (w_a + w_b + alpha~), each end's share w scale, and
// alpha~ = alpha / h^2.
struct Projection {
  uint32_t a, b;
  double rest, scale, ca, cb, alphaT;
};

using kernels::Kernel;
using kernels::Point4;

// Projects constraints [first, last), which must share no particle:
//   dl = (rest - len - alpha~ l) / (w_a + w_b + alpha~),  l += dl,
//   x_a += w_a dl d/len,  x_b -= w_b dl d/len,
// on positions x. The first iteration of a substep
// starts from l = 0 and does not read the multipliers; keepLambda false
// (one iteration a substep) skips storing them.
void ProjectRange(Kernel kernel, bool firstIteration, bool keepLambda, const Projection* ps,
                  double* lambda, Point4* x, size_t first, size_t last);

// A long-range attachment (Kim, Chentanez & Muller 2012): the particle may
// be no farther than `rest` from pin `pin` (UINT32_MAX: none).
struct Tether {
  uint32_t pin;
  double rest;
};
constexpr int kTethers = 2;  // a particle's nearest pins

// The per-particle part of a substep, on padded positions, velocities and
// the previous substep's positions; fext is the external force (wind) and w
// the inverse masses (0: pinned, never moved). tethers has kTethers a
// particle, or is null.
struct Particles {
  Point4 *x, *v, *prev;
  const Point4* fext;
  const double* w;
  const Tether* tethers;
  double gravity[3];
  double h, invH, keep;  // substep, 1 / h, velocity kept after damping
};

// Prediction for particles [b, e): prev = x, then for free particles
// v = (v + h (g + w f)) keep and x += h v.
void PredictRange(const Particles& p, size_t b, size_t e);
// The end of a substep for particles [b, e): clamps each free particle to
// its tethers in order, sets v = (x - prev) / h, then (predictNext) runs the
// next substep's prediction. A pin is read here but never written, so
// ranges may run in parallel.
void FinishRange(Kernel kernel, const Particles& p, bool predictNext, size_t b, size_t e);

}  // namespace sylva::particles::xpbd
