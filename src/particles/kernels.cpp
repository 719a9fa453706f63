#include "particles/kernels.h"

#include <immintrin.h>

namespace sylva::particles::kernels {
namespace {

[[gnu::target("avx")]] size_t SpringProductAvx(const SpringLinear* __restrict lin, size_t first, size_t last,
                                               double cx, double cv, const Point4* __restrict p,
                                               Point4* __restrict y) {
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
    const __m256d g = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(t), d), _mm256_mul_pd(_mm256_set1_pd(s), u));
    _mm256_store_pd(y[l.a].p, _mm256_add_pd(_mm256_load_pd(y[l.a].p), g));
    _mm256_store_pd(y[l.b].p, _mm256_sub_pd(_mm256_load_pd(y[l.b].p), g));
  }
  return last;
}

}  // namespace

Kernel Best() {
  static const Kernel best = __builtin_cpu_supports("avx") ? Kernel::kAvx : Kernel::kScalar;
  return best;
}

void SpringProductRange(Kernel kernel, const SpringLinear* lin, size_t first, size_t last, double cx, double cv,
                        const Point4* p, Point4* y) {
  if (kernel == Kernel::kAvx) first = SpringProductAvx(lin, first, last, cx, cv, p, y);
  for (size_t j = first; j < last; ++j) {
    SpringProduct(lin[j], cx, cv, p[lin[j].a].p, p[lin[j].b].p, y[lin[j].a].p, y[lin[j].b].p);
  }
}

}  // namespace sylva::particles::kernels
