// Vector kernels of the particles library's hot loops, internal to it.
//
// Solvers that stream over particles by index from constraint or spring
// records (XPBD projections, the implicit solver's spring products) are
// bound by memory operations more than arithmetic. They run on positions
// padded to four doubles (`Point4`, 32-byte aligned, the fourth 0), so one
// AVX load or store moves a particle, and the square roots and divisions of
// four records take one vector instruction each. Each kernel has a scalar
// twin doing the same operations in the same order (IEEE arithmetic is
// exactly rounded, and the build does not contract into FMA), so the two
// give bit-identical results; `Best()` picks AVX at run time where the
// processor has it, and the binary still runs where it does not.
#pragma once

#include <cfloat>
#include <cstddef>
#include <cstdint>

namespace sylva::particles::kernels {

// A position padded to 32 bytes; p[3] is 0.
struct alignas(32) Point4 {
  double p[4];
};

enum class Kernel { kScalar, kAvx };

// The widest kernel this processor runs.
Kernel Best();

// A spring linearised for the implicit solver (see Springs in system.h): its
// unit direction u (padded), ends and stiffnesses.
struct alignas(32) SpringLinear {
  double u[4];
  uint32_t a, b;
  double kt, kl, kd;
};

// y_a += g, y_b -= g for springs [first, last), which must share no
// particle, with d = p_a - p_b and
//   g = -(cx kt) d - (cx kl + cv kd) (u . d) u.
void SpringProductRange(Kernel kernel, const SpringLinear* lin, size_t first, size_t last,
                        double cx, double cv, const Point4* p, Point4* y);

// The same product for one spring on unpadded vectors (3 doubles).
inline void SpringProduct(const SpringLinear& l, double cx, double cv, const double* pa,
                          const double* pb, double* ya, double* yb) {
  const double d0 = pa[0] - pb[0], d1 = pa[1] - pb[1], d2 = pa[2] - pb[2];
  const double t = -cx * l.kt;
  const double s = -(cx * l.kl + cv * l.kd) * ((l.u[0] * d0 + l.u[1] * d1) + l.u[2] * d2);
  const double g0 = t * d0 + s * l.u[0], g1 = t * d1 + s * l.u[1], g2 = t * d2 + s * l.u[2];
  ya[0] += g0;
  ya[1] += g1;
  ya[2] += g2;
  yb[0] -= g0;
  yb[1] -= g1;
  yb[2] -= g2;
}

// Conjugate-gradient reductions over flat arrays of doubles (a Vec3 array
// is 3n of them), for [begin, end) with begin a multiple of 4. Each sum runs
// in four interleaved partial sums (element k into sum k mod 4, the AVX
// register's lanes), combined as (s0 + s1) + (s2 + s3).
//   Dot:     returns sum a_k b_k.
//   CgStep:  dv += alpha p, r -= alpha q; returns {sum r_k (r_k z_k),
//            sum r_k^2} with z the preconditioner (inverse diagonal).
double Dot(Kernel kernel, const double* a, const double* b, size_t begin, size_t end);
struct CgSums {
  double rz, rr;
};
CgSums CgStep(Kernel kernel, double alpha, const double* p, const double* q, const double* z,
              double* dv, double* r, size_t begin, size_t end);

// --- BulkSystem: single precision, structure of arrays ---

// One step's uniform fields, in single precision: gravity g (an
// acceleration), drag -(k1 + k2 |u|) u with u = v - wind (a force, times the
// inverse mass), the step h, and the magnitude limit of the fault check.
struct BulkParams {
  float gx, gy, gz, wx, wy, wz, k1, k2, h, limit;
};
struct BulkArrays {
  float *px, *py, *pz, *vx, *vy, *vz;
  const float* invMass;
};

// Symplectic Euler for particles [begin, end), in place, all in single
// precision, per particle:
//   u = v - wind, k = (k1 + k2 sqrt((ux^2 + uy^2) + uz^2)) w,
//   v' = v + h (g - k u), x' = x + h v',
// with an immovable particle (w = 0) kept where it is at zero velocity.
// old[0..5][i - begin] receive the previous px, py, pz, vx, vy, vz. Returns
// false if a new component c fails |c| <= limit (a NaN fails).
bool BulkAdvance(Kernel kernel, const BulkParams& q, const BulkArrays& a, size_t begin, size_t end,
                 float* const* old);

// flags[i - begin] |= 1 for the particles of [begin, end) whose new position
// b (the arrays, as doubles) has n . (b - p) < radius[i]: a plane collider's
// MayHit for a ball of that radius, computed as
// (n0 (b0 - p0) + n1 (b1 - p1)) + n2 (b2 - p2). The radii are read four at
// a time with the positions (no separate pass over them).
void BulkPlaneCandidates(Kernel kernel, const double* n, const double* p, const BulkArrays& a,
                         const float* radius, size_t begin, size_t end, uint8_t* flags);

// The same test, for a scene whose only collider is that plane: writes the
// indices (i - begin) of the particles of [begin, end) it flags that are
// movable (inverse mass not 0), in order, to idx (room for end - begin + 4:
// four lanes are written at a time) and returns their count.
size_t BulkPlaneCandidateList(Kernel kernel, const double* n, const double* p, const BulkArrays& a,
                              const float* radius, size_t begin, size_t end, uint16_t* idx);

// Resting contact on a single static plane (the bulk step's floor), four or
// eight particles at a time in double precision: the operations, in the same order,
// that RespondToContacts (its fast path for one resting contact at the start
// of the step), ProjectOut and the bulk step's rounding take for a particle
// that starts on or below the plane (d0 = n . (a - p) - r <= 0), approaches
// it no faster than the step's forces could make it, and ends the step
// strictly on it: same bits. The new velocity is
//   en = v . n, vt = v - en n, jn = max(0, -en),
//   out = (|vt| <= mu jn ? 0 : vt (1 - mu jn / |vt|)) + max(en, 0) n
// and the position (a - d0 n) + h out, rounded to floats (which must not
// cross the plane) and within the magnitude limit (x.x + v.v <= limit2).
// Every other particle (a faster approach, a start above the plane, a
// graze, a crossing after rounding, a NaN) is left for the general path.
//
// A particle that starts up to kRestSkin of its largest coordinate (at
// least 1) above the plane counts as on it (RespondToContacts' skin, which
// BulkSystem passes), and the rounding to floats is RoundOutside's: where
// it would cross the plane, a particle the response stopped keeps its
// start's floats if they lie within kRestRoundings ulps and on its side,
// and any other is pushed off along the normal by kRestPush ulps of x1's largest
// coordinate (at least 1) and rounded again; a second crossing is left for
// the general path.
constexpr double kRestPush = 4;  // RoundOutside's push, in ulps of the largest coordinate
constexpr double kRestSkin = 2 * kRestPush * double(FLT_EPSILON);  // twice the push
constexpr double kRestRoundings = 16;
struct PlaneRest {
  double n[3], p[3];
  double friction, h, limit2;
};
//
// BulkAdvance (AVX), BulkPlaneCandidateList and that resting kernel over
// [begin, end), at most kRestRange particles, on `lanes` lanes (4, or 8
// where RestLanes() is 8): the same bits as BulkAdvance and
// BulkPlaneCandidateList, then the general path's response to each
// candidate. Passes over the range, which stays in L1: on 8 lanes two,
// the advance and the candidate test eight particles at a time, then the
// resting kernel on the groups of eight with candidates, four groups at a
// time; on 4 lanes three, the advance, the candidate test four at a time,
// then the resting kernel on the runs of four with candidates, two at a
// time. Writes to idx the candidates the
// resting kernel leaves (for the general path), as
// BulkPlaneCandidateList, and returns their count; a tail of fewer than
// eight is advanced and its candidates listed. ANDs BulkAdvance's check
// and the radii's (each in [0, q.limit]) into *ok.
constexpr size_t kRestRange = 512;
size_t BulkAdvanceRestOnPlane(int lanes, const BulkParams& q, const PlaneRest& rest,
                              const BulkArrays& a, const float* radius, size_t begin, size_t end,
                              float* const* old, uint16_t* idx, bool* ok);
// The widest resting-floor path this processor runs: 8 lanes with AVX-512
// (F, DQ, VL) and BMI2, 4 with AVX, 0 without AVX (no vector path).
int RestLanes();

// --- System's particle-particle contacts (pairs.cpp) ---

// A pair screen: of the points x[from, to) (3 doubles each), writes to out
// the indices k (in order) of those within reach of p,
//   (d_x d_x + d_y d_y) + d_z d_z <= reach2,  d = x[k] - p
// (a NaN is not within), and returns how many. out has room for to - from.
// The vector path (kAvx where AVX-512 F and VL run: ScreenLanes() 8) takes
// eight points a step: three loads, deinterleaved by permutes, the indices
// compress-stored; the same indices as the scalar loop.
uint32_t ScreenCandidates(Kernel kernel, const double* x, uint32_t from, uint32_t to,
                          const double* p, double reach2, uint32_t* out);
// 8 where ScreenCandidates has its vector path, else 0.
int ScreenLanes();

}  // namespace sylva::particles::kernels
