#include "particles/xpbd.h"

#include <immintrin.h>

#include <cmath>

namespace sylva::particles::xpbd {
namespace {

constexpr double kDegenerate = 1e-24;  // squared length below which a constraint has no direction

template <bool kFirst>
void Scalar(bool keep, const Projection* __restrict ps, double* __restrict lambda,
            Point4* __restrict x, size_t first, size_t last) {
  for (size_t k = first; k < last; ++k) {
    const Projection& c = ps[k];
    double* pa = x[c.a].p;
    double* pb = x[c.b].p;
    const double d[3] = {pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]};
    const double len2 = (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2];
    if (!(len2 > kDegenerate)) {
      if (kFirst && keep) lambda[k] = 0;
      continue;
    }
    const double len = std::sqrt(len2);
    const double err = kFirst ? c.rest - len : c.rest - len - c.alphaT * lambda[k];
    if (keep) lambda[k] = (kFirst ? 0 : lambda[k]) + err * c.scale;
    const double q = err / len;
    for (int i = 0; i < 3; ++i) {
      const double dn = d[i] * q;
      pa[i] += c.ca * dn;
      pb[i] -= c.cb * dn;
    }
  }
}

template <bool kFirst>
[[gnu::target("avx")]] size_t Avx(bool keep, const Projection* __restrict ps,
                                  double* __restrict lambda, Point4* __restrict x, size_t first,
                                  size_t last) {
  size_t k = first;
  for (; k + 4 <= last; k += 4) {
    const Projection* c = ps + k;
    __m256d a[4], b[4], d[4];
    for (int l = 0; l < 4; ++l) {
      a[l] = _mm256_load_pd(x[c[l].a].p);
      b[l] = _mm256_load_pd(x[c[l].b].p);
      d[l] = _mm256_sub_pd(a[l], b[l]);  // the fourth lane is 0
    }
    // len2 = (d0^2 + d1^2) + d2^2 for the four, in the scalar kernel's order.
    const __m256d h01 = _mm256_hadd_pd(_mm256_mul_pd(d[0], d[0]), _mm256_mul_pd(d[1], d[1]));
    const __m256d h23 = _mm256_hadd_pd(_mm256_mul_pd(d[2], d[2]), _mm256_mul_pd(d[3], d[3]));
    const __m256d len2 = _mm256_add_pd(_mm256_permute2f128_pd(h01, h23, 0x20),
                                       _mm256_permute2f128_pd(h01, h23, 0x31));
    const __m256d len = _mm256_sqrt_pd(len2);
    __m256d err = _mm256_sub_pd(_mm256_set_pd(c[3].rest, c[2].rest, c[1].rest, c[0].rest), len);
    if (!kFirst) {
      const __m256d alphaT = _mm256_set_pd(c[3].alphaT, c[2].alphaT, c[1].alphaT, c[0].alphaT);
      err = _mm256_sub_pd(err, _mm256_mul_pd(alphaT, _mm256_loadu_pd(lambda + k)));
    }
    alignas(32) double e[4], q[4], l2[4];
    _mm256_store_pd(e, err);
    _mm256_store_pd(q, _mm256_div_pd(err, len));
    _mm256_store_pd(l2, len2);
    for (int l = 0; l < 4; ++l) {
      if (!(l2[l] > kDegenerate)) {
        if (kFirst && keep) lambda[k + size_t(l)] = 0;
        continue;
      }
      if (keep) lambda[k + size_t(l)] = (kFirst ? 0 : lambda[k + size_t(l)]) + e[l] * c[l].scale;
      const __m256d dn = _mm256_mul_pd(d[l], _mm256_broadcast_sd(q + l));
      _mm256_store_pd(x[c[l].a].p,
                      _mm256_add_pd(a[l], _mm256_mul_pd(_mm256_broadcast_sd(&c[l].ca), dn)));
      _mm256_store_pd(x[c[l].b].p,
                      _mm256_sub_pd(b[l], _mm256_mul_pd(_mm256_broadcast_sd(&c[l].cb), dn)));
    }
  }
  return k;
}

template <bool kFirst>
void Project(Kernel kernel, bool keep, const Projection* ps, double* lambda, Point4* x,
             size_t first, size_t last) {
  if (kernel == Kernel::kAvx) first = Avx<kFirst>(keep, ps, lambda, x, first, last);
  Scalar<kFirst>(keep, ps, lambda, x, first, last);
}

// --- particle passes ---

[[gnu::always_inline]] inline void Predict(const Particles& s, size_t i) {
  double* x = s.x[i].p;
  double* v = s.v[i].p;
  s.prev[i] = s.x[i];
  const double w = s.w[i];
  if (w == 0) return;
  for (int k = 0; k < 3; ++k) {
    v[k] = (v[k] + s.h * (s.gravity[k] + s.fext[i].p[k] * w)) * s.keep;
    x[k] += s.h * v[k];
  }
}

// Tethers, then the velocity. Whether a tether is taut is data, so the clamp
// is a select, not a branch.
[[gnu::always_inline]] inline void Finish(const Particles& s, size_t i) {
  double* x = s.x[i].p;
  if (s.tethers && s.w[i] != 0) {
    for (int t = 0; t < kTethers; ++t) {
      const Tether& th = s.tethers[i * kTethers + size_t(t)];
      if (th.pin == UINT32_MAX) continue;
      const double* q = s.x[th.pin].p;
      const double d0 = x[0] - q[0], d1 = x[1] - q[1], d2 = x[2] - q[2];
      const double len2 = (d0 * d0 + d1 * d1) + d2 * d2;
      const bool taut = len2 > th.rest * th.rest;
      const double f = th.rest / std::sqrt(taut ? len2 : 1.0);
      x[0] = taut ? q[0] + d0 * f : x[0];
      x[1] = taut ? q[1] + d1 * f : x[1];
      x[2] = taut ? q[2] + d2 * f : x[2];
    }
  }
  for (int k = 0; k < 3; ++k) s.v[i].p[k] = (x[k] - s.prev[i].p[k]) * s.invH;
}

// Rows a..d <-> columns: the 4x4 transpose, its own inverse.
[[gnu::target("avx"), gnu::always_inline]] inline void Transpose(__m256d& a, __m256d& b, __m256d& c,
                                                                 __m256d& d) {
  const __m256d t0 = _mm256_unpacklo_pd(a, b), t1 = _mm256_unpackhi_pd(a, b);
  const __m256d t2 = _mm256_unpacklo_pd(c, d), t3 = _mm256_unpackhi_pd(c, d);
  a = _mm256_permute2f128_pd(t0, t2, 0x20);
  b = _mm256_permute2f128_pd(t1, t3, 0x20);
  c = _mm256_permute2f128_pd(t0, t2, 0x31);
  d = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// Loads four padded points as three coordinate vectors.
struct Soa {
  __m256d c[3];
};

[[gnu::target("avx"), gnu::always_inline]] inline Soa Load4(const Point4* p0, const Point4* p1,
                                                            const Point4* p2, const Point4* p3) {
  __m256d a = _mm256_load_pd(p0->p), b = _mm256_load_pd(p1->p), c = _mm256_load_pd(p2->p),
          d = _mm256_load_pd(p3->p);
  Transpose(a, b, c, d);
  return {{a, b, c}};
}

[[gnu::target("avx"), gnu::always_inline]] inline void Store4(const Soa& s, Point4* p) {
  __m256d a = s.c[0], b = s.c[1], c = s.c[2], d = _mm256_setzero_pd();
  Transpose(a, b, c, d);
  _mm256_store_pd(p[0].p, a);
  _mm256_store_pd(p[1].p, b);
  _mm256_store_pd(p[2].p, c);
  _mm256_store_pd(p[3].p, d);
}

// Four particles a lane each, for blocks without a pin (a pin's lane would
// be written back, racing with the tethers that read it).
[[gnu::target("avx")]] size_t FinishAvx(const Particles& s, bool predictNext, size_t b, size_t e) {
  const __m256d h = _mm256_set1_pd(s.h), invH = _mm256_set1_pd(s.invH),
                keep = _mm256_set1_pd(s.keep);
  size_t i = b;
  for (; i + 4 <= e; i += 4) {
    const __m256d w = _mm256_loadu_pd(s.w + i);
    if (_mm256_movemask_pd(_mm256_cmp_pd(w, _mm256_setzero_pd(), _CMP_EQ_OQ)) != 0) {
      for (size_t j = i; j < i + 4; ++j) {
        Finish(s, j);
        if (predictNext) Predict(s, j);
      }
      continue;
    }
    Soa x = Load4(s.x + i, s.x + i + 1, s.x + i + 2, s.x + i + 3);
    if (s.tethers) {
      for (int t = 0; t < kTethers; ++t) {
        const Tether* th = s.tethers + i * kTethers + size_t(t);
        uint32_t pin[4];
        double rest[4];
        for (int l = 0; l < 4; ++l) {
          const Tether& tl = th[size_t(l) * kTethers];
          pin[l] = tl.pin == UINT32_MAX ? uint32_t(i) + uint32_t(l)
                                        : tl.pin;  // a lane that never clamps
          rest[l] = tl.pin == UINT32_MAX ? 1e300 : tl.rest;
        }
        const Soa q = Load4(s.x + pin[0], s.x + pin[1], s.x + pin[2], s.x + pin[3]);
        const __m256d r = _mm256_set_pd(rest[3], rest[2], rest[1], rest[0]);
        __m256d d[3];
        for (int k = 0; k < 3; ++k) d[k] = _mm256_sub_pd(x.c[k], q.c[k]);
        const __m256d len2 =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d[0], d[0]), _mm256_mul_pd(d[1], d[1])),
                          _mm256_mul_pd(d[2], d[2]));
        const __m256d taut = _mm256_cmp_pd(len2, _mm256_mul_pd(r, r), _CMP_GT_OQ);
        if (_mm256_movemask_pd(taut) == 0) continue;  // all slack (often so for a far pin's tether)
        const __m256d f =
            _mm256_div_pd(r, _mm256_sqrt_pd(_mm256_blendv_pd(_mm256_set1_pd(1.0), len2, taut)));
        for (int k = 0; k < 3; ++k) {
          x.c[k] = _mm256_blendv_pd(x.c[k], _mm256_add_pd(q.c[k], _mm256_mul_pd(d[k], f)), taut);
        }
      }
    }
    const Soa prev = Load4(s.prev + i, s.prev + i + 1, s.prev + i + 2, s.prev + i + 3);
    Soa v;
    for (int k = 0; k < 3; ++k) v.c[k] = _mm256_mul_pd(_mm256_sub_pd(x.c[k], prev.c[k]), invH);
    if (predictNext) {
      Store4(x, s.prev + i);
      const Soa f = Load4(s.fext + i, s.fext + i + 1, s.fext + i + 2, s.fext + i + 3);
      for (int k = 0; k < 3; ++k) {
        const __m256d a = _mm256_add_pd(_mm256_set1_pd(s.gravity[k]), _mm256_mul_pd(f.c[k], w));
        v.c[k] = _mm256_mul_pd(_mm256_add_pd(v.c[k], _mm256_mul_pd(h, a)), keep);
        x.c[k] = _mm256_add_pd(x.c[k], _mm256_mul_pd(h, v.c[k]));
      }
    }
    Store4(x, s.x + i);
    Store4(v, s.v + i);
  }
  return i;
}

}  // namespace

void PredictRange(const Particles& p, size_t b, size_t e) {
  for (size_t i = b; i < e; ++i) Predict(p, i);
}

void FinishRange(Kernel kernel, const Particles& p, bool predictNext, size_t b, size_t e) {
  if (kernel == Kernel::kAvx) b = FinishAvx(p, predictNext, b, e);
  for (size_t i = b; i < e; ++i) {
    Finish(p, i);
    if (predictNext) Predict(p, i);
  }
}

void ProjectRange(Kernel kernel, bool firstIteration, bool keepLambda, const Projection* ps,
                  double* lambda, Point4* x, size_t first, size_t last) {
  if (firstIteration) {
    Project<true>(kernel, keepLambda, ps, lambda, x, first, last);
  } else {
    Project<false>(kernel, keepLambda, ps, lambda, x, first, last);
  }
}

}  // namespace sylva::particles::xpbd
