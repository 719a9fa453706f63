#include "particles/kernels.h"

#include <immintrin.h>

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

}  // namespace sylva::particles::kernels
