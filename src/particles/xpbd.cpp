#include "particles/xpbd.h"

#include <immintrin.h>

#include <cmath>

namespace sylva::particles::xpbd {
namespace {

constexpr double kDegenerate = 1e-24;  // squared length below which a constraint has no direction

template <bool kFirst>
void Scalar(bool keep, const Projection* __restrict ps, double* __restrict lambda, Point4* __restrict x, size_t first,
            size_t last) {
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
[[gnu::target("avx")]] size_t Avx(bool keep, const Projection* __restrict ps, double* __restrict lambda,
                                  Point4* __restrict x, size_t first, size_t last) {
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
    const __m256d len2 =
        _mm256_add_pd(_mm256_permute2f128_pd(h01, h23, 0x20), _mm256_permute2f128_pd(h01, h23, 0x31));
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
      _mm256_store_pd(x[c[l].a].p, _mm256_add_pd(a[l], _mm256_mul_pd(_mm256_broadcast_sd(&c[l].ca), dn)));
      _mm256_store_pd(x[c[l].b].p, _mm256_sub_pd(b[l], _mm256_mul_pd(_mm256_broadcast_sd(&c[l].cb), dn)));
    }
  }
  return k;
}

template <bool kFirst>
void Project(Kernel kernel, bool keep, const Projection* ps, double* lambda, Point4* x, size_t first, size_t last) {
  if (kernel == Kernel::kAvx) first = Avx<kFirst>(keep, ps, lambda, x, first, last);
  Scalar<kFirst>(keep, ps, lambda, x, first, last);
}

}  // namespace

Kernel Best() {
  static const Kernel best = __builtin_cpu_supports("avx") ? Kernel::kAvx : Kernel::kScalar;
  return best;
}

void ProjectRange(Kernel kernel, bool firstIteration, bool keepLambda, const Projection* ps, double* lambda,
                  Point4* x, size_t first, size_t last) {
  if (firstIteration) {
    Project<true>(kernel, keepLambda, ps, lambda, x, first, last);
  } else {
    Project<false>(kernel, keepLambda, ps, lambda, x, first, last);
  }
}

}  // namespace sylva::particles::xpbd
