#include "particles/kernels.h"

#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>

#include "core/assert.h"

namespace sylva::particles::kernels {
namespace {

[[gnu::target("avx")]] size_t SpringProductAvx(const SpringLinear* __restrict lin, size_t first,
                                               size_t last, double cx, double cv,
                                               const Point4* __restrict p, Point4* __restrict y) {
  for (size_t j = first; j < last; ++j) {
    const SpringLinear& l = lin[j];
    const __m256d d = _mm256_sub_pd(_mm256_load_pd(p[l.a].p), _mm256_load_pd(p[l.b].p));
    const __m256d u = _mm256_load_pd(l.u);
    // (u0 d0 + u1 d1) + u2 d2, the scalar order.
    const __m256d m = _mm256_mul_pd(u, d);
    const __m128d lo = _mm256_castpd256_pd128(m), hi = _mm256_extractf128_pd(m, 1);
    const __m128d dot = _mm_add_sd(_mm_add_sd(lo, _mm_unpackhi_pd(lo, lo)), hi);
    const double t = -cx * l.kt;
    const double s = -(cx * l.kl + cv * l.kd) * _mm_cvtsd_f64(dot);
    const __m256d g =
        _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(t), d), _mm256_mul_pd(_mm256_set1_pd(s), u));
    _mm256_store_pd(y[l.a].p, _mm256_add_pd(_mm256_load_pd(y[l.a].p), g));
    _mm256_store_pd(y[l.b].p, _mm256_sub_pd(_mm256_load_pd(y[l.b].p), g));
  }
  return last;
}

[[gnu::always_inline]] inline double Combine(const double s[4]) {
  return (s[0] + s[1]) + (s[2] + s[3]);
}

double DotScalar(const double* __restrict a, const double* __restrict b, size_t i, size_t e,
                 double s[4]) {
  for (; i < e; ++i) s[i & 3] += a[i] * b[i];
  return Combine(s);
}

[[gnu::target("avx")]] double DotAvx(const double* __restrict a, const double* __restrict b,
                                     size_t i, size_t e) {
  __m256d acc = _mm256_setzero_pd();
  for (; i + 4 <= e; i += 4)
    acc = _mm256_add_pd(acc, _mm256_mul_pd(_mm256_loadu_pd(a + i), _mm256_loadu_pd(b + i)));
  alignas(32) double s[4];
  _mm256_store_pd(s, acc);
  return DotScalar(a, b, i, e, s);
}

CgSums CgStepScalar(double alpha, const double* __restrict p, const double* __restrict q,
                    const double* __restrict z, double* __restrict dv, double* __restrict r,
                    size_t i, size_t e, double rz[4], double rr[4]) {
  for (; i < e; ++i) {
    dv[i] += alpha * p[i];
    r[i] -= alpha * q[i];
    rz[i & 3] += r[i] * (r[i] * z[i]);
    rr[i & 3] += r[i] * r[i];
  }
  return {Combine(rz), Combine(rr)};
}

[[gnu::target("avx")]] CgSums CgStepAvx(double alpha, const double* __restrict p,
                                        const double* __restrict q, const double* __restrict z,
                                        double* __restrict dv, double* __restrict r, size_t i,
                                        size_t e) {
  const __m256d a = _mm256_set1_pd(alpha);
  __m256d rz = _mm256_setzero_pd(), rr = _mm256_setzero_pd();
  for (; i + 4 <= e; i += 4) {
    _mm256_storeu_pd(
        dv + i, _mm256_add_pd(_mm256_loadu_pd(dv + i), _mm256_mul_pd(a, _mm256_loadu_pd(p + i))));
    const __m256d ri =
        _mm256_sub_pd(_mm256_loadu_pd(r + i), _mm256_mul_pd(a, _mm256_loadu_pd(q + i)));
    _mm256_storeu_pd(r + i, ri);
    rz = _mm256_add_pd(rz, _mm256_mul_pd(ri, _mm256_mul_pd(ri, _mm256_loadu_pd(z + i))));
    rr = _mm256_add_pd(rr, _mm256_mul_pd(ri, ri));
  }
  alignas(32) double srz[4], srr[4];
  _mm256_store_pd(srz, rz);
  _mm256_store_pd(srr, rr);
  return CgStepScalar(alpha, p, q, z, dv, r, i, e, srz, srr);
}

// The bulk step for one particle; BulkAdvanceAvx does the same operations
// in the same order on eight.
[[gnu::always_inline]] inline bool BulkOne(const BulkParams& q, const BulkArrays& a, size_t i,
                                           float* const* old, size_t o) {
  const float x = a.px[i], y = a.py[i], z = a.pz[i];
  const float u = a.vx[i], v = a.vy[i], s = a.vz[i], w = a.invMass[i];
  const float rx = u - q.wx, ry = v - q.wy, rz = s - q.wz;
  const float speed = std::sqrt((rx * rx + ry * ry) + rz * rz);
  const float k = (q.k1 + q.k2 * speed) * w;
  const bool movable = w > 0;
  const float ax = (movable ? q.gx : 0.0f) - k * rx;
  const float ay = (movable ? q.gy : 0.0f) - k * ry;
  const float az = (movable ? q.gz : 0.0f) - k * rz;
  const float u1 = movable ? u + q.h * ax : 0.0f;
  const float v1 = movable ? v + q.h * ay : 0.0f;
  const float s1 = movable ? s + q.h * az : 0.0f;
  const float x1 = x + q.h * u1, y1 = y + q.h * v1, z1 = z + q.h * s1;
  old[0][o] = x, old[1][o] = y, old[2][o] = z, old[3][o] = u, old[4][o] = v, old[5][o] = s;
  a.px[i] = x1, a.py[i] = y1, a.pz[i] = z1, a.vx[i] = u1, a.vy[i] = v1, a.vz[i] = s1;
  return std::fabs(x1) <= q.limit && std::fabs(y1) <= q.limit && std::fabs(z1) <= q.limit &&
         std::fabs(u1) <= q.limit && std::fabs(v1) <= q.limit && std::fabs(s1) <= q.limit;
}

// All-ones lanes where |c| <= limit.
[[gnu::target("avx")]] inline __m256 Within(__m256 c, __m256 abs, __m256 limit) {
  return _mm256_cmp_ps(_mm256_and_ps(c, abs), limit, _CMP_LE_OQ);
}

// Returns the first index it did not do and ANDs its check into *ok.
[[gnu::target("avx")]] size_t BulkAdvanceAvx(const BulkParams& q, const BulkArrays& a, size_t i,
                                             size_t e, float* const* old, size_t o, bool* ok) {
  const __m256 gx = _mm256_set1_ps(q.gx), gy = _mm256_set1_ps(q.gy), gz = _mm256_set1_ps(q.gz);
  const __m256 wx = _mm256_set1_ps(q.wx), wy = _mm256_set1_ps(q.wy), wz = _mm256_set1_ps(q.wz);
  const __m256 k1 = _mm256_set1_ps(q.k1), k2 = _mm256_set1_ps(q.k2), h = _mm256_set1_ps(q.h);
  const __m256 zero = _mm256_setzero_ps(), limit = _mm256_set1_ps(q.limit);
  const __m256 abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  __m256 good = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (; i + 8 <= e; i += 8, o += 8) {
    const __m256 x = _mm256_loadu_ps(a.px + i), y = _mm256_loadu_ps(a.py + i);
    const __m256 z = _mm256_loadu_ps(a.pz + i), u = _mm256_loadu_ps(a.vx + i);
    const __m256 v = _mm256_loadu_ps(a.vy + i), s = _mm256_loadu_ps(a.vz + i);
    const __m256 w = _mm256_loadu_ps(a.invMass + i);
    const __m256 rx = _mm256_sub_ps(u, wx), ry = _mm256_sub_ps(v, wy), rz = _mm256_sub_ps(s, wz);
    const __m256 speed = _mm256_sqrt_ps(_mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(rx, rx), _mm256_mul_ps(ry, ry)), _mm256_mul_ps(rz, rz)));
    const __m256 k = _mm256_mul_ps(_mm256_add_ps(k1, _mm256_mul_ps(k2, speed)), w);
    const __m256 movable = _mm256_cmp_ps(w, zero, _CMP_GT_OQ);
    const __m256 ax = _mm256_sub_ps(_mm256_and_ps(movable, gx), _mm256_mul_ps(k, rx));
    const __m256 ay = _mm256_sub_ps(_mm256_and_ps(movable, gy), _mm256_mul_ps(k, ry));
    const __m256 az = _mm256_sub_ps(_mm256_and_ps(movable, gz), _mm256_mul_ps(k, rz));
    const __m256 u1 = _mm256_and_ps(movable, _mm256_add_ps(u, _mm256_mul_ps(h, ax)));
    const __m256 v1 = _mm256_and_ps(movable, _mm256_add_ps(v, _mm256_mul_ps(h, ay)));
    const __m256 s1 = _mm256_and_ps(movable, _mm256_add_ps(s, _mm256_mul_ps(h, az)));
    const __m256 x1 = _mm256_add_ps(x, _mm256_mul_ps(h, u1));
    const __m256 y1 = _mm256_add_ps(y, _mm256_mul_ps(h, v1));
    const __m256 z1 = _mm256_add_ps(z, _mm256_mul_ps(h, s1));
    _mm256_storeu_ps(old[0] + o, x), _mm256_storeu_ps(old[1] + o, y);
    _mm256_storeu_ps(old[2] + o, z), _mm256_storeu_ps(old[3] + o, u);
    _mm256_storeu_ps(old[4] + o, v), _mm256_storeu_ps(old[5] + o, s);
    _mm256_storeu_ps(a.px + i, x1), _mm256_storeu_ps(a.py + i, y1);
    _mm256_storeu_ps(a.pz + i, z1), _mm256_storeu_ps(a.vx + i, u1);
    _mm256_storeu_ps(a.vy + i, v1), _mm256_storeu_ps(a.vz + i, s1);
    good = _mm256_and_ps(
        good, _mm256_and_ps(_mm256_and_ps(Within(x1, abs, limit), Within(y1, abs, limit)),
                            _mm256_and_ps(Within(z1, abs, limit), Within(u1, abs, limit))));
    good = _mm256_and_ps(good, _mm256_and_ps(Within(v1, abs, limit), Within(s1, abs, limit)));
  }
  *ok = *ok && _mm256_movemask_ps(good) == 0xff;
  return i;
}

// (n0 y0 + n1 y1) + n2 y2, Eigen's order for a Vec3 dot product.
[[gnu::target("avx")]] inline __m256d Dot3(const __m256d n[3], __m256d y0, __m256d y1, __m256d y2) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(n[0], y0), _mm256_mul_pd(n[1], y1)),
                       _mm256_mul_pd(n[2], y2));
}

// n . (b - p) for the four positions b from i: the plane's candidate test
// (a candidate ends the step behind the plane moved out by its radius).
[[gnu::target("avx")]] inline __m256d PlaneDistance4(const __m256d n[3], const __m256d p[3],
                                                     const BulkArrays& a, size_t i) {
  return Dot3(n, _mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(a.px + i)), p[0]),
              _mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(a.py + i)), p[1]),
              _mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(a.pz + i)), p[2]));
}

[[gnu::target("avx")]] size_t BulkPlaneAvx(const double* n, const double* p, const BulkArrays& a,
                                           const float* radius, size_t i, size_t e,
                                           uint8_t* flags) {
  // One byte a lane from a four-bit mask.
  static constexpr uint32_t kBytes[16] = {0x00000000, 0x00000001, 0x00000100, 0x00000101,
                                          0x00010000, 0x00010001, 0x00010100, 0x00010101,
                                          0x01000000, 0x01000001, 0x01000100, 0x01000101,
                                          0x01010000, 0x01010001, 0x01010100, 0x01010101};
  const __m256d nv[3] = {_mm256_set1_pd(n[0]), _mm256_set1_pd(n[1]), _mm256_set1_pd(n[2])};
  const __m256d pv[3] = {_mm256_set1_pd(p[0]), _mm256_set1_pd(p[1]), _mm256_set1_pd(p[2])};
  uint8_t* f = flags;
  for (; i + 4 <= e; i += 4, f += 4) {
    const __m256d d = PlaneDistance4(nv, pv, a, i);
    const __m256d r = _mm256_cvtps_pd(_mm_loadu_ps(radius + i));
    const int mask = _mm256_movemask_pd(_mm256_cmp_pd(d, r, _CMP_LT_OQ));
    if (mask) {
      uint32_t bytes;
      std::memcpy(&bytes, f, 4);
      bytes |= kBytes[mask];
      std::memcpy(f, &bytes, 4);
    }
  }
  return i;
}

// The same test, listing the movable candidates' indices (relative to
// `first`) instead of flagging them.
[[gnu::target("avx")]] size_t PlaneListAvx(const double* n, const double* p, const BulkArrays& a,
                                           const float* radius, size_t& i, size_t e, size_t first,
                                           uint16_t* idx) {
  // The lanes of a four-bit mask as packed 16-bit offsets, and their count.
  static constexpr uint64_t kOffsets[16] = {
      0x0, 0x0,     0x1,     0x10000,     0x2,     0x20000,     0x20001,     0x200010000,
      0x3, 0x30000, 0x30001, 0x300010000, 0x30002, 0x300020000, 0x300020001, 0x3000200010000};
  const __m256d nv[3] = {_mm256_set1_pd(n[0]), _mm256_set1_pd(n[1]), _mm256_set1_pd(n[2])};
  const __m256d pv[3] = {_mm256_set1_pd(p[0]), _mm256_set1_pd(p[1]), _mm256_set1_pd(p[2])};
  size_t count = 0;
  for (; i + 4 <= e; i += 4) {
    const __m256d d = PlaneDistance4(nv, pv, a, i);
    const __m256d r = _mm256_cvtps_pd(_mm_loadu_ps(radius + i));
    const int below = _mm256_movemask_pd(_mm256_cmp_pd(d, r, _CMP_LT_OQ));
    if (!below) continue;
    const int movable =
        _mm_movemask_ps(_mm_cmp_ps(_mm_loadu_ps(a.invMass + i), _mm_setzero_ps(), _CMP_NEQ_UQ));
    const int mask = below & movable;
    // Four offsets at once (idx has room for four past the last), the
    // lanes kept packed.
    const uint64_t base = 0x0001000100010001ull * uint64_t(i - first);
    const uint64_t lanes = kOffsets[mask] + base;
    std::memcpy(idx + count, &lanes, 8);
    count += size_t(__builtin_popcount(unsigned(mask)));
  }
  return count;
}

[[gnu::target("avx")]] inline __m256d Abs(__m256d x) {
  return _mm256_andnot_pd(_mm256_set1_pd(-0.0), x);
}

// std::max(a, b) = a < b ? b : a, lane by lane: maxpd(b, a) is b > a ? b : a,
// the same for equal values (a signed zero included) and a NaN in either.
[[gnu::target("avx")]] inline __m256d Max(__m256d a, __m256d b) {
  return _mm256_max_pd(b, a);
}

// m ? b : a, lane by lane, for a mask m of all-ones or zero lanes, by bit
// operations: GCC turns blendv_pd on a comparison's mask into scalar code
// without AVX2 (it compares the mask's lanes as 64-bit integers).
[[gnu::target("avx")]] inline __m256d Select(__m256d m, __m256d a, __m256d b) {
  return _mm256_or_pd(_mm256_and_pd(m, b), _mm256_andnot_pd(m, a));
}

// The 4 lanes of a double-precision mask as a single-precision one (the
// high half of each lane's bits).
[[gnu::target("avx")]] inline __m128 Narrow(__m256d m) {
  const __m128 lo = _mm_castpd_ps(_mm256_castpd256_pd128(m));
  const __m128 hi = _mm_castpd_ps(_mm256_extractf128_pd(m, 1));
  return _mm_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1));
}

// Where y + (y - x) lies on the plane's side, radius r out (RoundOutside's
// Crosses for a rounded or kept point y seen from x; OnPlaneSide below on
// eight lanes).
[[gnu::target("avx")]] inline __m256d OnPlaneSide4(const __m256d n[3], const __m256d p[3],
                                                   const __m256d x[3], const __m256d y[3],
                                                   __m256d r) {
  __m256d by[3];
  for (int c = 0; c < 3; ++c)
    by[c] = _mm256_sub_pd(_mm256_add_pd(y[c], _mm256_sub_pd(y[c], x[c])), p[c]);
  return _mm256_cmp_pd(_mm256_sub_pd(Dot3(n, by[0], by[1], by[2]), r), _mm256_setzero_pd(),
                       _CMP_GE_OQ);
}

// The plane and the step on four lanes, for RestRunsAvx.
struct Rest4 {
  __m256d n[3], p[3], h, mh, half, mu, zero, one, tiny, tol, mtol, limit2;
  __m256d skin, eps, push, roundings;  // kRestSkin, FLT_EPSILON, kRestPush, kRestRoundings
};

// The resting kernel (see PlaneRest) on the candidates of G runs of four
// consecutive particles, run g starting at first + at[g] (its start state
// in old[..][at[g]], its advanced state in the arrays, its candidates the
// lanes of cand[g]), in double precision. As in RestGroupsAvx512, the
// runs' chains of dependent operations are interleaved statement by
// statement (one chain is longer than the processor looks ahead). Writes
// the particles it resolves to the arrays and appends the other
// candidates' offsets (at[g] + lane) to idx.
template <int G>
[[gnu::target("avx")]] void RestRunsAvx(const Rest4& k, const BulkArrays& ar, const float* radius,
                                        const float* const* old, size_t first, const uint16_t* at,
                                        const uint8_t* cand, uint16_t* idx, size_t* listed) {
  float* const to[6] = {ar.px + first, ar.py + first, ar.pz + first,
                        ar.vx + first, ar.vy + first, ar.vz + first};
  __m256d a[G][3], va[G][3], x[G][3], v[G][3], r[G];
  for (int g = 0; g < G; ++g) {
    for (int c = 0; c < 3; ++c) {
      a[g][c] = _mm256_cvtps_pd(_mm_loadu_ps(old[c] + at[g]));
      va[g][c] = _mm256_cvtps_pd(_mm_loadu_ps(old[3 + c] + at[g]));
      x[g][c] = _mm256_cvtps_pd(_mm_loadu_ps(to[c] + at[g]));
      v[g][c] = _mm256_cvtps_pd(_mm_loadu_ps(to[3 + c] + at[g]));
    }
    r[g] = _mm256_cvtps_pd(_mm_loadu_ps(radius + first + at[g]));
  }
  __m256d dv[G][3], u[G][3], d0[G], ok[G];
  for (int g = 0; g < G; ++g) {
    __m256d ap[3];
    for (int c = 0; c < 3; ++c) {
      dv[g][c] = _mm256_sub_pd(v[g][c], va[g][c]);
      const __m256d A = _mm256_mul_pd(k.h, dv[g][c]);
      u[g][c] = _mm256_sub_pd(_mm256_sub_pd(x[g][c], a[g][c]), _mm256_mul_pd(k.half, A));
      ap[c] = _mm256_sub_pd(a[g][c], k.p[c]);
    }
    // The plane's contact at the start (a candidate ends the step inside:
    // d1 < 0): d0 <= the skin (s = 0); on or below, at a - d0 n, and in
    // the skin above, at a itself. (Most lie within kRestSkin, which needs
    // no largest coordinate: see StartsInSkin.)
    d0[g] = _mm256_sub_pd(Dot3(k.n, ap[0], ap[1], ap[2]), r[g]);
    ok[g] = _mm256_cmp_pd(d0[g], k.skin, _CMP_LE_OQ);
  }
  int far = 0;
  for (int g = 0; g < G; ++g) far |= _mm256_movemask_pd(ok[g]) ^ 0xf;
  if (far) {
    for (int g = 0; g < G; ++g) {
      const __m256d amax = Max(k.one, Max(Max(Abs(a[g][0]), Abs(a[g][1])), Abs(a[g][2])));
      ok[g] = _mm256_cmp_pd(d0[g], _mm256_mul_pd(k.skin, amax), _CMP_LE_OQ);
    }
  }
  __m256d point[G][3], un[G];
  for (int g = 0; g < G; ++g) {
    const __m256d below = _mm256_cmp_pd(d0[g], k.zero, _CMP_LE_OQ);
    __m256d px[3];
    for (int c = 0; c < 3; ++c) {
      point[g][c] = Select(below, a[g][c], _mm256_sub_pd(a[g][c], _mm256_mul_pd(d0[g], k.n[c])));
      px[c] = _mm256_sub_pd(point[g][c], x[g][c]);
    }
    // Not a graze (sliding along the plane within rounding).
    const __m256d xmax = Max(k.one, Max(Max(Abs(x[g][0]), Abs(x[g][1])), Abs(x[g][2])));
    const __m256d umax = Max(k.tiny, Max(Max(Abs(u[g][0]), Abs(u[g][1])), Abs(u[g][2])));
    un[g] = Dot3(k.n, u[g][0], u[g][1], u[g][2]);
    const __m256d slides = _mm256_and_pd(
        _mm256_cmp_pd(Dot3(k.n, px[0], px[1], px[2]), _mm256_mul_pd(k.tol, xmax), _CMP_LE_OQ),
        _mm256_cmp_pd(un[g], _mm256_mul_pd(k.mtol, umax), _CMP_GE_OQ));
    ok[g] = _mm256_andnot_pd(slides, ok[g]);
  }
  // Resting: no faster toward the plane than the step's forces made it.
  // The response.
  __m256d en[G], vt[G][3], change[G], len[G];
  for (int g = 0; g < G; ++g) {
    const __m256d gained =
        Max(k.zero, _mm256_mul_pd(k.mh, Dot3(k.n, dv[g][0], dv[g][1], dv[g][2])));
    ok[g] = _mm256_andnot_pd(
        _mm256_cmp_pd(_mm256_xor_pd(un[g], _mm256_set1_pd(-0.0)), gained, _CMP_GT_OQ), ok[g]);
    en[g] = Dot3(k.n, v[g][0], v[g][1], v[g][2]);
    const __m256d jn = Max(k.zero, _mm256_xor_pd(en[g], _mm256_set1_pd(-0.0)));
    for (int c = 0; c < 3; ++c) vt[g][c] = _mm256_sub_pd(v[g][c], _mm256_mul_pd(en[g], k.n[c]));
    change[g] = _mm256_mul_pd(k.mu, jn);
    len[g] = _mm256_sqrt_pd(_mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(vt[g][0], vt[g][0]), _mm256_mul_pd(vt[g][1], vt[g][1])),
        _mm256_mul_pd(vt[g][2], vt[g][2])));
  }
  __m256d out[G][3], x1[G][3];
  for (int g = 0; g < G; ++g) {
    const __m256d stops = _mm256_cmp_pd(len[g], change[g], _CMP_LE_OQ);
    const __m256d keep = _mm256_sub_pd(k.one, _mm256_div_pd(change[g], len[g]));
    const __m256d up = Max(en[g], k.zero);
    __m256d x1p[3];
    for (int c = 0; c < 3; ++c) {
      const __m256d f = _mm256_andnot_pd(stops, _mm256_mul_pd(vt[g][c], keep));  // 0 where stops
      out[g][c] = _mm256_add_pd(f, _mm256_mul_pd(up, k.n[c]));
      x1[g][c] = _mm256_add_pd(point[g][c], _mm256_mul_pd(k.h, out[g][c]));
      x1p[c] = _mm256_sub_pd(x1[g][c], k.p[c]);
    }
    // Ends on the plane: no second contact, nothing to project.
    ok[g] = _mm256_and_pd(
        ok[g],
        _mm256_cmp_pd(_mm256_sub_pd(Dot3(k.n, x1p[0], x1p[1], x1p[2]), r[g]), k.zero, _CMP_GE_OQ));
  }
  for (int g = 0; g < G; ++g) {
    // Rounded to floats on the plane's side (RoundOutside): a rounding's
    // displacement, doubled, must not cross it. A rounding that changes
    // nothing passes too: its doubled point is x1 itself, on the plane's
    // side by the test above.
    __m128 xf[3];
    __m256d rx[3];
    for (int c = 0; c < 3; ++c) {
      xf[c] = _mm256_cvtpd_ps(x1[g][c]);
      rx[c] = _mm256_cvtps_pd(xf[c]);
    }
    const __m256d crosses = _mm256_andnot_pd(OnPlaneSide4(k.n, k.p, x1[g], rx, r[g]), ok[g]);
    if (_mm256_movemask_pd(crosses) & cand[g]) {
      // Where it crosses: a particle the response stopped (out = 0) keeps
      // its start's floats if they lie within kRestRoundings ulps of x1's
      // largest coordinate and on its side; any other is pushed off along
      // the normal by kRestPush such ulps and rounded again, which must not cross
      // (else the general path pushes again).
      const __m256d scale =
          _mm256_mul_pd(k.eps, Max(k.one, Max(Max(Abs(x1[g][0]), Abs(x1[g][1])), Abs(x1[g][2]))));
      const __m256d rest =
          _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(out[g][0], k.zero, _CMP_EQ_OQ),
                                      _mm256_cmp_pd(out[g][1], k.zero, _CMP_EQ_OQ)),
                        _mm256_cmp_pd(out[g][2], k.zero, _CMP_EQ_OQ));
      const __m256d apart =
          Max(Max(Abs(_mm256_sub_pd(a[g][0], x1[g][0])), Abs(_mm256_sub_pd(a[g][1], x1[g][1]))),
              Abs(_mm256_sub_pd(a[g][2], x1[g][2])));
      const __m256d keeps = _mm256_and_pd(
          _mm256_and_pd(crosses, rest),
          _mm256_and_pd(_mm256_cmp_pd(apart, _mm256_mul_pd(k.roundings, scale), _CMP_LE_OQ),
                        OnPlaneSide4(k.n, k.p, x1[g], a[g], r[g])));
      const __m256d push = _mm256_mul_pd(k.push, scale);
      __m128 pf[3];
      __m256d pr[3];
      for (int c = 0; c < 3; ++c) {
        pf[c] = _mm256_cvtpd_ps(_mm256_add_pd(x1[g][c], _mm256_mul_pd(push, k.n[c])));
        pr[c] = _mm256_cvtps_pd(pf[c]);
      }
      const __m256d pushed =
          _mm256_andnot_pd(keeps, _mm256_and_pd(crosses, OnPlaneSide4(k.n, k.p, x1[g], pr, r[g])));
      const __m128 keepsf = Narrow(keeps), pushedf = Narrow(pushed);
      for (int c = 0; c < 3; ++c) {
        xf[c] = _mm_blendv_ps(xf[c], _mm256_cvtpd_ps(a[g][c]), keepsf);
        xf[c] = _mm_blendv_ps(xf[c], pf[c], pushedf);
        rx[c] = Select(keeps, rx[c], a[g][c]);
        rx[c] = Select(pushed, rx[c], pr[c]);
      }
      ok[g] = _mm256_andnot_pd(_mm256_andnot_pd(_mm256_or_pd(keeps, pushed), crosses), ok[g]);
    }
    // Within the magnitude limit.
    const __m256d xx =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(rx[0], rx[0]), _mm256_mul_pd(rx[1], rx[1])),
                      _mm256_mul_pd(rx[2], rx[2]));
    const __m256d vv = _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(out[g][0], out[g][0]), _mm256_mul_pd(out[g][1], out[g][1])),
        _mm256_mul_pd(out[g][2], out[g][2]));
    ok[g] = _mm256_and_pd(ok[g], _mm256_cmp_pd(_mm256_add_pd(xx, vv), k.limit2, _CMP_LE_OQ));
    __m128 fv[3];
    for (int c = 0; c < 3; ++c) fv[c] = _mm256_cvtpd_ps(out[g][c]);
    const int done = _mm256_movemask_pd(ok[g]) & cand[g];
    if (done == 0xf) {
      for (int c = 0; c < 3; ++c) {
        _mm_storeu_ps(to[c] + at[g], xf[c]);
        _mm_storeu_ps(to[3 + c] + at[g], fv[c]);
      }
      continue;
    }
    if (done) {
      // The resolved lanes over the others' floats (the same values back).
      const __m128i bit = _mm_setr_epi32(1, 2, 4, 8);
      const __m128 m =
          _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(done), bit), bit));
      for (int c = 0; c < 6; ++c) {
        const __m128 now = _mm_loadu_ps(to[c] + at[g]);
        _mm_storeu_ps(to[c] + at[g], _mm_blendv_ps(now, c < 3 ? xf[c] : fv[c - 3], m));
      }
    }
    // The rest to the general path.
    for (unsigned left = unsigned(cand[g] & ~done); left; left &= left - 1)
      idx[(*listed)++] = uint16_t(at[g] + unsigned(__builtin_ctz(left)));
  }
}

// BulkAdvanceAvx's step, the plane's candidate test (PlaneListAvx's) and
// the resting kernel over [i, e), as AdvanceRestAvx512 below on four lanes,
// in three passes over that range (at most a chunk, which stays in L1): the
// advance; the candidate test four at a time, listing the runs of four with
// candidates; the resting kernel on those runs. (Fused, the advance and the
// test need more than AVX's 16 registers and were slower.) Returns the
// first index it did not do; the candidates the resting kernel leaves go
// to idx (relative to first), in order, *count counting them.
[[gnu::target("avx")]] size_t AdvanceRestAvx(const BulkParams& q, const PlaneRest& rq,
                                             const BulkArrays& ar, const float* radius, size_t i,
                                             size_t e, size_t first, float* const* old,
                                             uint16_t* idx, size_t* count, bool* good) {
  SYLVA_ASSERT(e - i <= kRestRange);
  const size_t begin = i;
  i = BulkAdvanceAvx(q, ar, i, e, old, i - first, good);
  const Rest4 k{{_mm256_set1_pd(rq.n[0]), _mm256_set1_pd(rq.n[1]), _mm256_set1_pd(rq.n[2])},
                {_mm256_set1_pd(rq.p[0]), _mm256_set1_pd(rq.p[1]), _mm256_set1_pd(rq.p[2])},
                _mm256_set1_pd(rq.h),
                _mm256_set1_pd(-rq.h),
                _mm256_set1_pd(0.5),
                _mm256_set1_pd(rq.friction),
                _mm256_setzero_pd(),
                _mm256_set1_pd(1.0),
                _mm256_set1_pd(1e-300),
                _mm256_set1_pd(1e-12),
                _mm256_set1_pd(-1e-12),
                _mm256_set1_pd(rq.limit2),
                _mm256_set1_pd(kRestSkin),
                _mm256_set1_pd(double(FLT_EPSILON)),
                _mm256_set1_pd(kRestPush),
                _mm256_set1_pd(kRestRoundings)};
  // The candidates (PlaneListAvx): movable particles that end behind the
  // plane; a run of four listed if it has any (without a branch). The
  // radius, in [0, limit] (a bad one clears *good: see BadRadiusIn).
  uint16_t at[kRestRange / 4];
  uint8_t cand[kRestRange / 4];
  size_t runs = 0;
  const __m128 zerof = _mm_setzero_ps(), limit = _mm_set1_ps(q.limit);
  __m128 radii = _mm_castsi128_ps(_mm_set1_epi32(-1));
  for (size_t j = begin; j < i; j += 4) {
    const __m128 rf = _mm_loadu_ps(radius + j);
    radii = _mm_and_ps(
        radii, _mm_and_ps(_mm_cmp_ps(rf, zerof, _CMP_GE_OQ), _mm_cmp_ps(rf, limit, _CMP_LE_OQ)));
    const __m256d d = PlaneDistance4(k.n, k.p, ar, j);
    const int candidates =
        _mm256_movemask_pd(_mm256_cmp_pd(d, _mm256_cvtps_pd(rf), _CMP_LT_OQ)) &
        _mm_movemask_ps(_mm_cmp_ps(_mm_loadu_ps(ar.invMass + j), zerof, _CMP_NEQ_UQ));
    at[runs] = uint16_t(j - first);
    cand[runs] = uint8_t(candidates);
    runs += candidates != 0;
  }
  *good = *good && _mm_movemask_ps(radii) == 0xf;
  // The resting kernel on the listed runs.
  size_t g = 0;
  for (; g + 2 <= runs; g += 2)
    RestRunsAvx<2>(k, ar, radius, old, first, at + g, cand + g, idx, count);
  for (; g < runs; ++g) RestRunsAvx<1>(k, ar, radius, old, first, at + g, cand + g, idx, count);
  return i;
}

// --- The same resting kernel on eight lanes (AVX-512 F, DQ and VL) ---

#define SYLVA_AVX512 gnu::target("avx512f,avx512dq,avx512vl,bmi2")
// GCC 12's AVX-512 conversions start from _mm512_undefined_*(), which
// -Wmaybe-uninitialized reports once inlined.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

// (n0 y0 + n1 y1) + n2 y2 on eight lanes.
[[SYLVA_AVX512]] inline __m512d Dot3(const __m512d n[3], __m512d y0, __m512d y1, __m512d y2) {
  return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(n[0], y0), _mm512_mul_pd(n[1], y1)),
                       _mm512_mul_pd(n[2], y2));
}

[[SYLVA_AVX512]] inline __m512d Abs(__m512d x) {
  return _mm512_andnot_pd(_mm512_set1_pd(-0.0), x);
}

[[SYLVA_AVX512]] inline __m512d Neg(__m512d x) {
  return _mm512_xor_pd(x, _mm512_set1_pd(-0.0));
}

// std::max(a, b), as Max above.
[[SYLVA_AVX512]] inline __m512d Max(__m512d a, __m512d b) {
  return _mm512_max_pd(b, a);
}

// The plane and the step on eight lanes, for RestGroupsAvx512.
struct Rest8 {
  __m512d n[3], p[3], h, mh, half, mu, zero, one, tiny, tol, mtol, limit2, sign;
  __m512d skin, eps, push, roundings;  // kRestSkin, FLT_EPSILON, kRestPush, kRestRoundings
  // A magnitude that six coordinates and speeds may each reach (in floats)
  // with x.x + v.v <= limit2 certain (see RestGroupsAvx512).
  __m256 small;
};

// Where the start a, d0 from the plane (radius out), lies at most kRestSkin
// of its largest coordinate (at least 1) above it (see PlaneRest). Most
// lie within kRestSkin (a resting particle, which the push left at most
// half as far), which needs no largest coordinate; the others of the
// candidates cand take it.
[[SYLVA_AVX512]] inline __mmask8 StartsInSkin(const Rest8& k, const __m512d a[3], __m512d d0,
                                              __mmask8 cand) {
  const __mmask8 near = _mm512_cmp_pd_mask(d0, k.skin, _CMP_LE_OQ);
  if (!(cand & ~near)) return near;
  const __m512d skin = _mm512_mul_pd(k.skin, Max(k.one, Max(Max(Abs(a[0]), Abs(a[1])), Abs(a[2]))));
  return _mm512_cmp_pd_mask(d0, skin, _CMP_LE_OQ);
}

// Where the rounded points rx, seen from x, do not cross the plane
// (RoundOutside's Crosses): rx + (rx - x) on the plane's side, radius r
// out. Only a comparison reads the dot product, so with kUp (see
// RestGroupsAvx512) its second component serves.
template <bool kUp>
[[SYLVA_AVX512]] inline __mmask8 OnPlaneSide(const Rest8& k, const __m512d x[3],
                                             const __m512d rx[3], __m512d r) {
  __m512d by[3];
  for (int c = 0; c < 3; ++c) {
    if (!kUp || c == 1)
      by[c] = _mm512_sub_pd(_mm512_add_pd(rx[c], _mm512_sub_pd(rx[c], x[c])), k.p[c]);
  }
  const __m512d bn = kUp ? by[1] : Dot3(k.n, by[0], by[1], by[2]);
  return _mm512_cmp_pd_mask(_mm512_sub_pd(bn, r), k.zero, _CMP_GE_OQ);
}

// The resting kernel on the candidates of G groups of eight consecutive
// particles, group g starting at first + at[g] (its start state in
// old[..][at[g]], its advanced state in the arrays, its candidates the
// lanes of cand[g]). Each group's chain of dependent operations is long
// (about 40 deep, through a square root and a division), longer than the
// processor's scheduler can look ahead past, so the groups' computations
// are interleaved, statement by statement, for the vector units to work
// on G chains at once. Writes the particles it resolves to the arrays and
// appends the other candidates' offsets (at[g] + lane) to idx.
//
// kUp: the plane's normal is (+0, 1, +0) exactly (a floor in a y-up
// world), and the kernel skips the products by 0 and 1, the same bits.
// A candidate's inputs are finite but for their second components: the
// candidate test takes n . x with every component, so an infinite or NaN
// x_0 or x_2 (which a non-finite start or velocity across the normal
// makes) is no candidate; but 0 x_0 + x_1 + 0 x_2 is -infinity for an
// overflowed x_1, where the general path's 0 times an infinity is NaN. A
// lane with v_1 infinite is left to the general path (below); one with a
// non-finite a_1 ends at a NaN, one with x_1 infinite and v_1 finite
// approaches faster than its forces could make it: both fail a test and
// are left too (found by fuzzing against the scalar path). For finite y,
// 0 y is a zero with y's sign, Z(y) = y & -0.0, and 1 y = y, so a dot
// product n . y is y_1 where y_1 is not zero, and a zero of some sign
// where it is. Where a dot product only meets a comparison, the sign of a
// zero is irrelevant and y_1 serves; where its sign can reach a stored
// bit, the kernel takes the exact operations, or leaves the lane to the
// general path:
//   en = n . v: v_1 where v_1 is not -0 (a lane with v_1 = -0 is left:
//     there en's sign is that of all three components), so
//   vt = v - en n is (v_0 - Z(v_1), +0, v_2 - Z(v_1)) (v_1 - v_1 = +0),
//   |vt|^2 = vt_0^2 + vt_2^2 (adding +0 to a square changes nothing),
//   up = max(en, 0) is +0 or positive, so out = f + up n is
//   (f_0 + 0, up, f_2 + 0) (f_1 = +0 vt_1 keep = +0): never -0;
//   d0 = n . (a - p) - r: (a_1 - p_1) - r, whose zero may have another sign
//   than the general path's, and so may the point, a - d0 n (a_1 - d0, and
//   a_c - Z(d0) on the other two); but the end, point + h out, adds to it
//   h out, which is +0 where it is a zero, so no sign of a zero of the
//   point reaches it.
template <int G, bool kUp>
[[SYLVA_AVX512]] void RestGroupsAvx512(const Rest8& k, const BulkArrays& ar, const float* radius,
                                       const float* const* old, size_t first, const uint16_t* at,
                                       const __mmask8* cand, uint16_t* idx, size_t* listed) {
  float* const to[6] = {ar.px + first, ar.py + first, ar.pz + first,
                        ar.vx + first, ar.vy + first, ar.vz + first};
  __m512d a[G][3], va[G][3], v[G][3], x[G][3], r[G];
  for (int g = 0; g < G; ++g) {
    for (int c = 0; c < 3; ++c) {
      a[g][c] = _mm512_cvtps_pd(_mm256_loadu_ps(old[c] + at[g]));
      va[g][c] = _mm512_cvtps_pd(_mm256_loadu_ps(old[3 + c] + at[g]));
      x[g][c] = _mm512_cvtps_pd(_mm256_loadu_ps(to[c] + at[g]));
      v[g][c] = _mm512_cvtps_pd(_mm256_loadu_ps(to[3 + c] + at[g]));
    }
    r[g] = _mm512_cvtps_pd(_mm256_loadu_ps(radius + first + at[g]));
  }
  __m512d dv[G][3], A[G][3], u[G][3];
  for (int g = 0; g < G; ++g) {
    for (int c = 0; c < 3; ++c) {
      dv[g][c] = _mm512_sub_pd(v[g][c], va[g][c]);
      A[g][c] = _mm512_mul_pd(k.h, dv[g][c]);
      u[g][c] = _mm512_sub_pd(_mm512_sub_pd(x[g][c], a[g][c]), _mm512_mul_pd(k.half, A[g][c]));
    }
  }
  // The plane's contact at the start (a candidate ends the step inside:
  // d1 < 0): d0 <= skin (s = 0).
  __m512d d0[G], point[G][3], un[G];
  __mmask8 ok[G], along[G], grazes = 0;
  for (int g = 0; g < G; ++g) {
    if constexpr (kUp) {
      d0[g] = _mm512_sub_pd(_mm512_sub_pd(a[g][1], k.p[1]), r[g]);
      // (fpclass 0x04 | 0x08 | 0x10: -0, +infinity, -infinity.)
      ok[g] = StartsInSkin(k, a[g], d0[g], cand[g]) & ~_mm512_fpclass_pd_mask(v[g][1], 0x1c);
      const __mmask8 below = _mm512_cmp_pd_mask(d0[g], k.zero, _CMP_LE_OQ);
      // On or below: a - d0 n; in the skin above: a (a_c - Z(d0) is a_c
      // there, d0 > 0).
      const __m512d z = _mm512_and_pd(d0[g], k.sign);
      point[g][0] = _mm512_sub_pd(a[g][0], z);
      point[g][1] = _mm512_mask_sub_pd(a[g][1], below, a[g][1], d0[g]);
      point[g][2] = _mm512_sub_pd(a[g][2], z);
      un[g] = u[g][1];
    } else {
      __m512d ap[3];
      for (int c = 0; c < 3; ++c) ap[c] = _mm512_sub_pd(a[g][c], k.p[c]);
      d0[g] = _mm512_sub_pd(Dot3(k.n, ap[0], ap[1], ap[2]), r[g]);
      ok[g] = StartsInSkin(k, a[g], d0[g], cand[g]);
      const __mmask8 below = _mm512_cmp_pd_mask(d0[g], k.zero, _CMP_LE_OQ);
      for (int c = 0; c < 3; ++c)
        point[g][c] = _mm512_mask_sub_pd(a[g][c], below, a[g][c], _mm512_mul_pd(d0[g], k.n[c]));
      un[g] = Dot3(k.n, u[g][0], u[g][1], u[g][2]);
    }
    // Not a graze (sliding along the plane within rounding): a path not
    // into the plane (rare for a candidate), ending on it.
    const __m512d umax = Max(k.tiny, Max(Max(Abs(u[g][0]), Abs(u[g][1])), Abs(u[g][2])));
    along[g] = _mm512_cmp_pd_mask(un[g], _mm512_mul_pd(k.mtol, umax), _CMP_GE_OQ);
    grazes |= along[g] & ok[g];
  }
  if (grazes) {
    for (int g = 0; g < G; ++g) {
      __m512d px[3];
      for (int c = 0; c < 3; ++c) px[c] = _mm512_sub_pd(point[g][c], x[g][c]);
      const __m512d xmax = Max(k.one, Max(Max(Abs(x[g][0]), Abs(x[g][1])), Abs(x[g][2])));
      const __m512d pn = kUp ? px[1] : Dot3(k.n, px[0], px[1], px[2]);
      ok[g] &= ~(_mm512_cmp_pd_mask(pn, _mm512_mul_pd(k.tol, xmax), _CMP_LE_OQ) & along[g]);
    }
  }
  // Resting: no faster toward the plane than the step's forces made it.
  // The response.
  __m512d en[G], vt[G][3], change[G], len[G];
  for (int g = 0; g < G; ++g) {
    const __m512d dn = kUp ? dv[g][1] : Dot3(k.n, dv[g][0], dv[g][1], dv[g][2]);
    const __m512d gained = Max(k.zero, _mm512_mul_pd(k.mh, dn));
    ok[g] &= ~_mm512_cmp_pd_mask(Neg(un[g]), gained, _CMP_GT_OQ);
    if constexpr (kUp) {
      en[g] = v[g][1];
      const __m512d z = _mm512_and_pd(en[g], k.sign);
      vt[g][0] = _mm512_sub_pd(v[g][0], z);
      vt[g][1] = k.zero;
      vt[g][2] = _mm512_sub_pd(v[g][2], z);
      len[g] = _mm512_sqrt_pd(
          _mm512_add_pd(_mm512_mul_pd(vt[g][0], vt[g][0]), _mm512_mul_pd(vt[g][2], vt[g][2])));
    } else {
      en[g] = Dot3(k.n, v[g][0], v[g][1], v[g][2]);
      for (int c = 0; c < 3; ++c) vt[g][c] = _mm512_sub_pd(v[g][c], _mm512_mul_pd(en[g], k.n[c]));
      len[g] = _mm512_sqrt_pd(_mm512_add_pd(
          _mm512_add_pd(_mm512_mul_pd(vt[g][0], vt[g][0]), _mm512_mul_pd(vt[g][1], vt[g][1])),
          _mm512_mul_pd(vt[g][2], vt[g][2])));
    }
    change[g] = _mm512_mul_pd(k.mu, Max(k.zero, Neg(en[g])));
  }
  __m512d out[G][3], x1[G][3];
  for (int g = 0; g < G; ++g) {
    const __mmask8 stops = _mm512_cmp_pd_mask(len[g], change[g], _CMP_LE_OQ);
    const __m512d keep = _mm512_sub_pd(k.one, _mm512_div_pd(change[g], len[g]));
    const __m512d up = Max(en[g], k.zero);
    for (int c = 0; c < 3; ++c) {
      if (kUp && c == 1) {
        out[g][c] = up;
      } else {
        const __m512d f = _mm512_maskz_mul_pd(__mmask8(~stops), vt[g][c], keep);  // 0 where stops
        out[g][c] = _mm512_add_pd(f, kUp ? k.zero : _mm512_mul_pd(up, k.n[c]));
      }
      x1[g][c] = _mm512_add_pd(point[g][c], _mm512_mul_pd(k.h, out[g][c]));
    }
    // Ends on the plane: no second contact, nothing to project.
    __m512d x1n;
    if constexpr (kUp) {
      x1n = _mm512_sub_pd(x1[g][1], k.p[1]);
    } else {
      __m512d x1p[3];
      for (int c = 0; c < 3; ++c) x1p[c] = _mm512_sub_pd(x1[g][c], k.p[c]);
      x1n = Dot3(k.n, x1p[0], x1p[1], x1p[2]);
    }
    ok[g] &= _mm512_cmp_pd_mask(_mm512_sub_pd(x1n, r[g]), k.zero, _CMP_GE_OQ);
  }
  for (int g = 0; g < G; ++g) {
    // Rounded to floats on the plane's side (RoundOutside): a rounding's
    // displacement, doubled, must not cross it. (A rounding that changes
    // nothing passes here too: its doubled displacement is 0, the test
    // above.)
    __m256 xf[3];
    __m512d rx[3];
    for (int c = 0; c < 3; ++c) {
      xf[c] = _mm512_cvtpd_ps(x1[g][c]);
      rx[c] = _mm512_cvtps_pd(xf[c]);
    }
    const __mmask8 crosses = ~OnPlaneSide<kUp>(k, x1[g], rx, r[g]) & ok[g] & cand[g];
    if (crosses) {
      // Where it crosses: a particle the response stopped (out = 0) keeps
      // its start's floats if they lie within kRestRoundings ulps of x1's
      // largest coordinate and on its side; any other is pushed off along
      // the normal by kRestPush such ulps and rounded again, which must not cross
      // (else the general path pushes again).
      const __m512d scale =
          _mm512_mul_pd(k.eps, Max(k.one, Max(Max(Abs(x1[g][0]), Abs(x1[g][1])), Abs(x1[g][2]))));
      const __mmask8 rest = _mm512_cmp_pd_mask(out[g][0], k.zero, _CMP_EQ_OQ) &
                            _mm512_cmp_pd_mask(out[g][1], k.zero, _CMP_EQ_OQ) &
                            _mm512_cmp_pd_mask(out[g][2], k.zero, _CMP_EQ_OQ);
      const __m512d apart =
          Max(Max(Abs(_mm512_sub_pd(a[g][0], x1[g][0])), Abs(_mm512_sub_pd(a[g][1], x1[g][1]))),
              Abs(_mm512_sub_pd(a[g][2], x1[g][2])));
      const __mmask8 keeps =
          crosses & rest &
          _mm512_cmp_pd_mask(apart, _mm512_mul_pd(k.roundings, scale), _CMP_LE_OQ) &
          OnPlaneSide<kUp>(k, x1[g], a[g], r[g]);
      const __m512d push = _mm512_mul_pd(k.push, scale);
      __m256 pf[3];
      __m512d pr[3];
      for (int c = 0; c < 3; ++c) {
        const __m512d base =
            _mm512_add_pd(x1[g][c], kUp ? (c == 1 ? push : k.zero) : _mm512_mul_pd(push, k.n[c]));
        pf[c] = _mm512_cvtpd_ps(base);
        pr[c] = _mm512_cvtps_pd(pf[c]);
      }
      const __mmask8 pushed = crosses & ~keeps & OnPlaneSide<kUp>(k, x1[g], pr, r[g]);
      for (int c = 0; c < 3; ++c) {
        xf[c] = _mm256_mask_mov_ps(xf[c], keeps, _mm512_cvtpd_ps(a[g][c]));
        xf[c] = _mm256_mask_mov_ps(xf[c], pushed, pf[c]);
        rx[c] = _mm512_mask_mov_pd(rx[c], keeps, a[g][c]);
        rx[c] = _mm512_mask_mov_pd(rx[c], pushed, pr[c]);
      }
      ok[g] &= ~crosses | keeps | pushed;
    }
    // Within the magnitude limit: x.x + v.v <= limit2, certain where the
    // six floats stored are each within k.small (|v_c| is at most its
    // float's, times 1 + 2^-24), else taken.
    __m256 of[3];
    __mmask8 small = 0xff;
    const __m256 absf = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    for (int c = 0; c < 3; ++c) {
      of[c] = _mm512_cvtpd_ps(out[g][c]);
      small &= _mm256_cmp_ps_mask(_mm256_and_ps(xf[c], absf), k.small, _CMP_LE_OQ) &
               _mm256_cmp_ps_mask(_mm256_and_ps(of[c], absf), k.small, _CMP_LE_OQ);
    }
    if (ok[g] & cand[g] & ~small) {
      const __m512d xx =
          _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(rx[0], rx[0]), _mm512_mul_pd(rx[1], rx[1])),
                        _mm512_mul_pd(rx[2], rx[2]));
      const __m512d vv = _mm512_add_pd(
          _mm512_add_pd(_mm512_mul_pd(out[g][0], out[g][0]), _mm512_mul_pd(out[g][1], out[g][1])),
          _mm512_mul_pd(out[g][2], out[g][2]));
      ok[g] &= _mm512_cmp_pd_mask(_mm512_add_pd(xx, vv), k.limit2, _CMP_LE_OQ);
    }
    const __mmask8 done = ok[g] & cand[g];
    for (int c = 0; c < 3; ++c) {
      _mm256_mask_storeu_ps(to[c] + at[g], done, xf[c]);
      _mm256_mask_storeu_ps(to[3 + c] + at[g], done, of[c]);
    }
    // The rest to the general path.
    for (unsigned left = unsigned(cand[g] & ~done); left; left &= left - 1)
      idx[(*listed)++] = uint16_t(at[g] + unsigned(__builtin_ctz(left)));
  }
}

// A float L with 6 (L (1 + 2^-24))^2 (1 + 2^-50) <= limit2: six
// coordinates and speeds each within L (the speeds' floats within L) have
// x.x + v.v <= limit2 in doubles.
float SmallEnough(double limit2) {
  const double l = std::sqrt(limit2 / 6) * (1 - 0x1p-20);
  float f = float(std::min(l, double(FLT_MAX)));
  if (double(f) > l) f = std::nextafter(f, 0.0f);
  return f;
}

// BulkAdvanceAvx's step, the plane's candidate test (PlaneListAvx's) and
// the resting kernel over [i, e), eight particles at a time, in two passes
// over that range (at most a chunk, which stays in L1): the advance and
// the candidate test, listing the groups of eight with candidates, then
// the resting kernel on those groups four at a time (RestGroupsAvx512): the
// same operations on the same values as the three kernels in turn. Returns
// the first index it did not do; the candidates the resting kernel leaves
// go to idx (relative to first), in order, *count counting them.
[[SYLVA_AVX512]] size_t AdvanceRestAvx512(const BulkParams& q, const PlaneRest& rq,
                                          const BulkArrays& ar, const float* radius, size_t i,
                                          size_t e, size_t first, float* const* old, uint16_t* idx,
                                          size_t* count, bool* good) {
  const __m256 gx = _mm256_set1_ps(q.gx), gy = _mm256_set1_ps(q.gy), gz = _mm256_set1_ps(q.gz);
  const __m256 wx = _mm256_set1_ps(q.wx), wy = _mm256_set1_ps(q.wy), wz = _mm256_set1_ps(q.wz);
  const __m256 k1 = _mm256_set1_ps(q.k1), k2 = _mm256_set1_ps(q.k2), hf = _mm256_set1_ps(q.h);
  const __m256 zerof = _mm256_setzero_ps(), limit = _mm256_set1_ps(q.limit);
  const __m256 absf = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  __m256 within = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  const __m512d n[3] = {_mm512_set1_pd(rq.n[0]), _mm512_set1_pd(rq.n[1]), _mm512_set1_pd(rq.n[2])};
  const __m512d p[3] = {_mm512_set1_pd(rq.p[0]), _mm512_set1_pd(rq.p[1]), _mm512_set1_pd(rq.p[2])};
  // The groups with candidates: their offsets from first and candidates.
  uint16_t at[kRestRange / 8];
  __mmask8 cand[kRestRange / 8];
  size_t groups = 0;
  SYLVA_ASSERT(e - i <= kRestRange);
  for (; i + 8 <= e; i += 8) {
    const size_t o = i - first;
    // The advance (BulkAdvanceAvx).
    const __m256 x0 = _mm256_loadu_ps(ar.px + i), y0 = _mm256_loadu_ps(ar.py + i);
    const __m256 z0 = _mm256_loadu_ps(ar.pz + i), u0 = _mm256_loadu_ps(ar.vx + i);
    const __m256 v0 = _mm256_loadu_ps(ar.vy + i), s0 = _mm256_loadu_ps(ar.vz + i);
    const __m256 w = _mm256_loadu_ps(ar.invMass + i);
    const __m256 rx0 = _mm256_sub_ps(u0, wx), ry0 = _mm256_sub_ps(v0, wy);
    const __m256 rz0 = _mm256_sub_ps(s0, wz);
    const __m256 speed = _mm256_sqrt_ps(_mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(rx0, rx0), _mm256_mul_ps(ry0, ry0)), _mm256_mul_ps(rz0, rz0)));
    const __m256 kd = _mm256_mul_ps(_mm256_add_ps(k1, _mm256_mul_ps(k2, speed)), w);
    const __m256 movable = _mm256_cmp_ps(w, zerof, _CMP_GT_OQ);
    const __m256 ax = _mm256_sub_ps(_mm256_and_ps(movable, gx), _mm256_mul_ps(kd, rx0));
    const __m256 ay = _mm256_sub_ps(_mm256_and_ps(movable, gy), _mm256_mul_ps(kd, ry0));
    const __m256 az = _mm256_sub_ps(_mm256_and_ps(movable, gz), _mm256_mul_ps(kd, rz0));
    const __m256 u1 = _mm256_and_ps(movable, _mm256_add_ps(u0, _mm256_mul_ps(hf, ax)));
    const __m256 v1 = _mm256_and_ps(movable, _mm256_add_ps(v0, _mm256_mul_ps(hf, ay)));
    const __m256 s1 = _mm256_and_ps(movable, _mm256_add_ps(s0, _mm256_mul_ps(hf, az)));
    const __m256 x1f = _mm256_add_ps(x0, _mm256_mul_ps(hf, u1));
    const __m256 y1f = _mm256_add_ps(y0, _mm256_mul_ps(hf, v1));
    const __m256 z1f = _mm256_add_ps(z0, _mm256_mul_ps(hf, s1));
    _mm256_storeu_ps(old[0] + o, x0), _mm256_storeu_ps(old[1] + o, y0);
    _mm256_storeu_ps(old[2] + o, z0), _mm256_storeu_ps(old[3] + o, u0);
    _mm256_storeu_ps(old[4] + o, v0), _mm256_storeu_ps(old[5] + o, s0);
    within = _mm256_and_ps(
        within, _mm256_and_ps(_mm256_and_ps(Within(x1f, absf, limit), Within(y1f, absf, limit)),
                              _mm256_and_ps(Within(z1f, absf, limit), Within(u1, absf, limit))));
    within = _mm256_and_ps(within, _mm256_and_ps(Within(v1, absf, limit), Within(s1, absf, limit)));
    _mm256_storeu_ps(ar.px + i, x1f), _mm256_storeu_ps(ar.py + i, y1f);
    _mm256_storeu_ps(ar.pz + i, z1f), _mm256_storeu_ps(ar.vx + i, u1);
    _mm256_storeu_ps(ar.vy + i, v1), _mm256_storeu_ps(ar.vz + i, s1);
    // The candidates (PlaneListAvx): movable particles that end behind the
    // plane; the group listed if it has any (without a branch).
    // The radius, in [0, limit] (a bad one clears *good: see BadRadiusIn).
    const __m256 rf = _mm256_loadu_ps(radius + i);
    within = _mm256_and_ps(within, _mm256_and_ps(_mm256_cmp_ps(rf, zerof, _CMP_GE_OQ),
                                                 _mm256_cmp_ps(rf, limit, _CMP_LE_OQ)));
    const __m512d r = _mm512_cvtps_pd(rf);
    const __m512d d =
        Dot3(n, _mm512_sub_pd(_mm512_cvtps_pd(x1f), p[0]),
             _mm512_sub_pd(_mm512_cvtps_pd(y1f), p[1]), _mm512_sub_pd(_mm512_cvtps_pd(z1f), p[2]));
    const __mmask8 candidates =
        _mm512_cmp_pd_mask(d, r, _CMP_LT_OQ) & _mm256_cmp_ps_mask(w, zerof, _CMP_NEQ_UQ);
    at[groups] = uint16_t(o);
    cand[groups] = candidates;
    groups += candidates != 0;
  }
  *good = *good && _mm256_movemask_ps(within) == 0xff;
  // The resting kernel on the listed groups.
  const Rest8 k{{n[0], n[1], n[2]},
                {p[0], p[1], p[2]},
                _mm512_set1_pd(rq.h),
                _mm512_set1_pd(-q.h),
                _mm512_set1_pd(0.5),
                _mm512_set1_pd(rq.friction),
                _mm512_setzero_pd(),
                _mm512_set1_pd(1.0),
                _mm512_set1_pd(1e-300),
                _mm512_set1_pd(1e-12),
                _mm512_set1_pd(-1e-12),
                _mm512_set1_pd(rq.limit2),
                _mm512_set1_pd(-0.0),
                _mm512_set1_pd(kRestSkin),
                _mm512_set1_pd(double(FLT_EPSILON)),
                _mm512_set1_pd(kRestPush),
                _mm512_set1_pd(kRestRoundings),
                _mm256_set1_ps(SmallEnough(rq.limit2))};
  // The floor of a y-up world, (+0, 1, +0) to the bit: RestGroupsAvx512's kUp.
  const double up[3] = {0.0, 1.0, 0.0};
  size_t g = 0;
  if (std::memcmp(rq.n, up, sizeof up) == 0) {
    for (; g + 4 <= groups; g += 4)
      RestGroupsAvx512<4, true>(k, ar, radius, old, first, at + g, cand + g, idx, count);
    for (; g < groups; ++g)
      RestGroupsAvx512<1, true>(k, ar, radius, old, first, at + g, cand + g, idx, count);
    return i;
  }
  for (; g + 4 <= groups; g += 4)
    RestGroupsAvx512<4, false>(k, ar, radius, old, first, at + g, cand + g, idx, count);
  for (; g < groups; ++g)
    RestGroupsAvx512<1, false>(k, ar, radius, old, first, at + g, cand + g, idx, count);
  return i;
}

#pragma GCC diagnostic pop
#undef SYLVA_AVX512

// --- Pair screen (System, pairs.cpp) ---

uint32_t ScreenScalar(const double* __restrict x, uint32_t k, uint32_t to,
                      const double* __restrict p, double reach2, uint32_t* __restrict out) {
  const double px = p[0], py = p[1], pz = p[2];
  uint32_t m = 0;
  for (; k < to; ++k) {
    const double* xk = x + 3 * size_t(k);
    const double dx = xk[0] - px, dy = xk[1] - py, dz = xk[2] - pz;
    out[m] = k;  // without a branch: kept where it passes
    m += uint32_t(dx * dx + dy * dy + dz * dz <= reach2);
  }
  return m;
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// Eight points a step: their 24 doubles in three registers, split into
// x, y and z by two permutes each.
[[gnu::target("avx512f,avx512vl")]] uint32_t ScreenAvx512(const double* __restrict x, uint32_t k,
                                                          uint32_t to, const double* __restrict p,
                                                          double reach2, uint32_t* __restrict out) {
  const __m512i ax = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0);
  const __m512i bx = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
  const __m512i ay = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0);
  const __m512i by = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
  const __m512i az = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0);
  const __m512i bz = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
  const __m512d px = _mm512_set1_pd(p[0]), py = _mm512_set1_pd(p[1]), pz = _mm512_set1_pd(p[2]);
  const __m512d r2 = _mm512_set1_pd(reach2);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  uint32_t m = 0;
  for (; k < to; k += 8) {
    const uint32_t left = std::min<uint32_t>(8, to - k);
    const double* xk = x + 3 * size_t(k);
    __m512d a, b, c;
    if (left == 8) {
      a = _mm512_loadu_pd(xk);
      b = _mm512_loadu_pd(xk + 8);
      c = _mm512_loadu_pd(xk + 16);
    } else {
      // The 3 left doubles, masked: lanes past the end read nothing.
      const uint32_t d = 3 * left;
      a = _mm512_maskz_loadu_pd(__mmask8((1u << std::min(d, 8u)) - 1), xk);
      b = _mm512_maskz_loadu_pd(__mmask8((1u << (d > 8 ? std::min(d - 8, 8u) : 0u)) - 1), xk + 8);
      c = _mm512_maskz_loadu_pd(__mmask8((1u << (d > 16 ? d - 16 : 0u)) - 1), xk + 16);
    }
    const __m512d X = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, ax, b), bx, c);
    const __m512d Y = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, ay, b), by, c);
    const __m512d Z = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, az, b), bz, c);
    const __m512d dx = _mm512_sub_pd(X, px), dy = _mm512_sub_pd(Y, py), dz = _mm512_sub_pd(Z, pz);
    const __m512d d2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                     _mm512_mul_pd(dz, dz));
    const __mmask8 in = _mm512_cmp_pd_mask(d2, r2, _CMP_LE_OQ) & __mmask8((1u << left) - 1);
    const __m256i index = _mm256_add_epi32(_mm256_set1_epi32(int(k)), lane);
    // Compressed in a register, then stored: a masked compress-store to
    // memory is microcoded on AMD's Zen 4, an order of magnitude slower
    // (it was a third of the 10,000 balls' gathering). A full block stores
    // all 8 lanes (out has room: m <= k - from); the last, through a copy.
    const __m256i kept = _mm256_maskz_compress_epi32(in, index);
    if (left == 8) {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + m), kept);
    } else {
      alignas(32) uint32_t tail[8];
      _mm256_store_si256(reinterpret_cast<__m256i*>(tail), kept);
      for (int j = 0, e = __builtin_popcount(in); j < e; ++j) out[m + uint32_t(j)] = tail[j];
    }
    m += uint32_t(__builtin_popcount(in));
  }
  return m;
}
#pragma GCC diagnostic pop

}  // namespace

double Dot(Kernel kernel, const double* a, const double* b, size_t begin, size_t end) {
  if (kernel == Kernel::kAvx) return DotAvx(a, b, begin, end);
  double s[4] = {};
  return DotScalar(a, b, begin, end, s);
}

CgSums CgStep(Kernel kernel, double alpha, const double* p, const double* q, const double* z,
              double* dv, double* r, size_t begin, size_t end) {
  if (kernel == Kernel::kAvx) return CgStepAvx(alpha, p, q, z, dv, r, begin, end);
  double rz[4] = {}, rr[4] = {};
  return CgStepScalar(alpha, p, q, z, dv, r, begin, end, rz, rr);
}

Kernel Best() {
  // cpu_init first: Best() may run in a static constructor, before main.
  static const Kernel best =
      (__builtin_cpu_init(), __builtin_cpu_supports("avx")) ? Kernel::kAvx : Kernel::kScalar;
  return best;
}

void SpringProductRange(Kernel kernel, const SpringLinear* lin, size_t first, size_t last,
                        double cx, double cv, const Point4* p, Point4* y) {
  if (kernel == Kernel::kAvx) first = SpringProductAvx(lin, first, last, cx, cv, p, y);
  for (size_t j = first; j < last; ++j) {
    SpringProduct(lin[j], cx, cv, p[lin[j].a].p, p[lin[j].b].p, y[lin[j].a].p, y[lin[j].b].p);
  }
}

bool BulkAdvance(Kernel kernel, const BulkParams& q, const BulkArrays& a, size_t begin, size_t end,
                 float* const* old) {
  bool ok = true;
  size_t i = begin;
  if (kernel == Kernel::kAvx) i = BulkAdvanceAvx(q, a, begin, end, old, 0, &ok);
  for (; i < end; ++i) ok &= BulkOne(q, a, i, old, i - begin);
  return ok;
}

void BulkPlaneCandidates(Kernel kernel, const double* n, const double* p, const BulkArrays& a,
                         const float* radius, size_t begin, size_t end, uint8_t* flags) {
  size_t i = begin;
  if (kernel == Kernel::kAvx) i = BulkPlaneAvx(n, p, a, radius, begin, end, flags);
  for (; i < end; ++i) {
    const double d = (n[0] * (double(a.px[i]) - p[0]) + n[1] * (double(a.py[i]) - p[1])) +
                     n[2] * (double(a.pz[i]) - p[2]);
    flags[i - begin] |= d < double(radius[i]);
  }
}

int RestLanes() {
  static const int lanes = Best() != Kernel::kAvx ? 0
                           : (__builtin_cpu_init(), __builtin_cpu_supports("avx512f") &&
                                                        __builtin_cpu_supports("avx512dq") &&
                                                        __builtin_cpu_supports("avx512vl") &&
                                                        __builtin_cpu_supports("bmi2"))
                               ? 8
                               : 4;
  return lanes;
}

size_t BulkPlaneCandidateList(Kernel kernel, const double* n, const double* p, const BulkArrays& a,
                              const float* radius, size_t begin, size_t end, uint16_t* idx) {
  size_t i = begin, count = 0;
  if (kernel == Kernel::kAvx) count = PlaneListAvx(n, p, a, radius, i, end, begin, idx);
  for (; i < end; ++i) {
    const double d = (n[0] * (double(a.px[i]) - p[0]) + n[1] * (double(a.py[i]) - p[1])) +
                     n[2] * (double(a.pz[i]) - p[2]);
    if (d < double(radius[i]) && a.invMass[i] != 0) idx[count++] = uint16_t(i - begin);
  }
  return count;
}

size_t BulkAdvanceRestOnPlane(int lanes, const BulkParams& q, const PlaneRest& rest,
                              const BulkArrays& a, const float* radius, size_t begin, size_t end,
                              float* const* old, uint16_t* idx, bool* ok) {
  SYLVA_ASSERT((lanes == 4 || lanes == 8) && lanes <= RestLanes());
  size_t count = 0;
  const size_t tail =
      lanes == 8 ? AdvanceRestAvx512(q, rest, a, radius, begin, end, begin, old, idx, &count, ok)
                 : AdvanceRestAvx(q, rest, a, radius, begin, end, begin, old, idx, &count, ok);
  // The tail (fewer than eight): the advance, and its candidates to the
  // general path.
  for (size_t i = tail; i < end; ++i) *ok &= BulkOne(q, a, i, old, i - begin);
  for (size_t i = tail; i < end; ++i) {
    *ok &= radius[i] >= 0.0f && radius[i] <= q.limit;
    const double d =
        (rest.n[0] * (double(a.px[i]) - rest.p[0]) + rest.n[1] * (double(a.py[i]) - rest.p[1])) +
        rest.n[2] * (double(a.pz[i]) - rest.p[2]);
    if (d < double(radius[i]) && a.invMass[i] != 0) idx[count++] = uint16_t(i - begin);
  }
  return count;
}

int ScreenLanes() {
  static const int lanes = (__builtin_cpu_init(),
                            __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl"))
                               ? 8
                               : 0;
  return lanes;
}

uint32_t ScreenCandidates(Kernel kernel, const double* x, uint32_t from, uint32_t to,
                          const double* p, double reach2, uint32_t* out) {
  if (kernel == Kernel::kAvx && ScreenLanes() == 8)
    return ScreenAvx512(x, from, to, p, reach2, out);
  return ScreenScalar(x, from, to, p, reach2, out);
}

}  // namespace sylva::particles::kernels
