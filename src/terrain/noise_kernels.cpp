// AVX2 twins of the gradient-noise sample functions in noise_kernels.h:
// eight samples a vector, the same operations in the same order, so the
// results are the scalar ones bit for bit. Gradient tables are looked up
// with one permute per component (8 entries; 16 for 3D as two permutes and
// a blend on bit 3 of the index).
#include "terrain/noise_kernels.h"

#include <immintrin.h>

namespace sylva::terrain::kernels {
namespace {

#define SYLVA_AVX2 [[gnu::target("avx2")]]

SYLVA_AVX2 inline __m256 FadeV(__m256 t) {
  const __m256 t3 = _mm256_mul_ps(_mm256_mul_ps(t, t), t);
  const __m256 inner = _mm256_add_ps(
      _mm256_mul_ps(t,
                    _mm256_sub_ps(_mm256_mul_ps(t, _mm256_set1_ps(6.0f)), _mm256_set1_ps(15.0f))),
      _mm256_set1_ps(10.0f));
  return _mm256_mul_ps(t3, inner);
}

SYLVA_AVX2 inline __m256 LerpV(__m256 a, __m256 b, __m256 t) {
  return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}

SYLVA_AVX2 inline __m256i HashV(__m256i k) {
  k = _mm256_mullo_epi32(k, _mm256_set1_epi32(int32_t(kMul1)));
  k = _mm256_xor_si256(k, _mm256_srli_epi32(k, 15));
  return _mm256_mullo_epi32(k, _mm256_set1_epi32(int32_t(kMul2)));
}

SYLVA_AVX2 inline __m256 Grad2V(__m256i h, __m256 dx, __m256 dy, __m256 gx, __m256 gy) {
  const __m256i g = _mm256_srli_epi32(h, 29);
  return _mm256_add_ps(_mm256_mul_ps(_mm256_permutevar8x32_ps(gx, g), dx),
                       _mm256_mul_ps(_mm256_permutevar8x32_ps(gy, g), dy));
}

struct Tables3 {
  __m256 xl, xh, yl, yh, zl, zh;
};

SYLVA_AVX2 inline __m256 Pick16(__m256 lo, __m256 hi, __m256i g, __m256 sel) {
  return _mm256_blendv_ps(_mm256_permutevar8x32_ps(lo, g), _mm256_permutevar8x32_ps(hi, g), sel);
}

SYLVA_AVX2 inline __m256 Grad3V(__m256i h, __m256 dx, __m256 dy, __m256 dz, const Tables3& t) {
  const __m256i g = _mm256_srli_epi32(h, 28);
  // Bit 3 of the index moved to the sign bit selects the upper table.
  const __m256 sel = _mm256_castsi256_ps(_mm256_slli_epi32(g, 28));
  const __m256 gx = Pick16(t.xl, t.xh, g, sel), gy = Pick16(t.yl, t.yh, g, sel);
  const __m256 gz = Pick16(t.zl, t.zh, g, sel);
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(gx, dx), _mm256_mul_ps(gy, dy)),
                       _mm256_mul_ps(gz, dz));
}

SYLVA_AVX2 inline __m256 Noise2V(__m256i key, __m256 x, __m256 y, __m256 gx, __m256 gy) {
  const __m256 flx = _mm256_floor_ps(x), fly = _mm256_floor_ps(y);
  const __m256i px = _mm256_set1_epi32(int32_t(kPrimeX)), py = _mm256_set1_epi32(int32_t(kPrimeY));
  const __m256i xp0 = _mm256_mullo_epi32(_mm256_cvttps_epi32(flx), px);
  const __m256i yp0 = _mm256_mullo_epi32(_mm256_cvttps_epi32(fly), py);
  const __m256i xp1 = _mm256_add_epi32(xp0, px), yp1 = _mm256_add_epi32(yp0, py);
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 fx = _mm256_sub_ps(x, flx), fy = _mm256_sub_ps(y, fly);
  const __m256 fx1 = _mm256_sub_ps(fx, one), fy1 = _mm256_sub_ps(fy, one);
  const __m256 u = FadeV(fx), v = FadeV(fy);
  const __m256i k0 = _mm256_xor_si256(key, yp0), k1 = _mm256_xor_si256(key, yp1);
  const __m256 n00 = Grad2V(HashV(_mm256_xor_si256(k0, xp0)), fx, fy, gx, gy);
  const __m256 n10 = Grad2V(HashV(_mm256_xor_si256(k0, xp1)), fx1, fy, gx, gy);
  const __m256 n01 = Grad2V(HashV(_mm256_xor_si256(k1, xp0)), fx, fy1, gx, gy);
  const __m256 n11 = Grad2V(HashV(_mm256_xor_si256(k1, xp1)), fx1, fy1, gx, gy);
  return _mm256_mul_ps(LerpV(LerpV(n00, n10, u), LerpV(n01, n11, u), v), _mm256_set1_ps(kScale2));
}

SYLVA_AVX2 inline __m256 Noise3V(__m256i key, __m256 x, __m256 y, __m256 z, const Tables3& t) {
  const __m256 flx = _mm256_floor_ps(x), fly = _mm256_floor_ps(y), flz = _mm256_floor_ps(z);
  const __m256i px = _mm256_set1_epi32(int32_t(kPrimeX)), py = _mm256_set1_epi32(int32_t(kPrimeY));
  const __m256i pz = _mm256_set1_epi32(int32_t(kPrimeZ));
  const __m256i xp0 = _mm256_mullo_epi32(_mm256_cvttps_epi32(flx), px);
  const __m256i yp0 = _mm256_mullo_epi32(_mm256_cvttps_epi32(fly), py);
  const __m256i zp0 = _mm256_mullo_epi32(_mm256_cvttps_epi32(flz), pz);
  const __m256i xp1 = _mm256_add_epi32(xp0, px), yp1 = _mm256_add_epi32(yp0, py);
  const __m256i zp1 = _mm256_add_epi32(zp0, pz);
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 fx = _mm256_sub_ps(x, flx), fy = _mm256_sub_ps(y, fly), fz = _mm256_sub_ps(z, flz);
  const __m256 fx1 = _mm256_sub_ps(fx, one), fy1 = _mm256_sub_ps(fy, one);
  const __m256 fz1 = _mm256_sub_ps(fz, one);
  const __m256 u = FadeV(fx), v = FadeV(fy), w = FadeV(fz);
  const __m256i k00 = _mm256_xor_si256(_mm256_xor_si256(key, yp0), zp0);
  const __m256i k10 = _mm256_xor_si256(_mm256_xor_si256(key, yp1), zp0);
  const __m256i k01 = _mm256_xor_si256(_mm256_xor_si256(key, yp0), zp1);
  const __m256i k11 = _mm256_xor_si256(_mm256_xor_si256(key, yp1), zp1);
  const __m256 n000 = Grad3V(HashV(_mm256_xor_si256(k00, xp0)), fx, fy, fz, t);
  const __m256 n100 = Grad3V(HashV(_mm256_xor_si256(k00, xp1)), fx1, fy, fz, t);
  const __m256 n010 = Grad3V(HashV(_mm256_xor_si256(k10, xp0)), fx, fy1, fz, t);
  const __m256 n110 = Grad3V(HashV(_mm256_xor_si256(k10, xp1)), fx1, fy1, fz, t);
  const __m256 n001 = Grad3V(HashV(_mm256_xor_si256(k01, xp0)), fx, fy, fz1, t);
  const __m256 n101 = Grad3V(HashV(_mm256_xor_si256(k01, xp1)), fx1, fy, fz1, t);
  const __m256 n011 = Grad3V(HashV(_mm256_xor_si256(k11, xp0)), fx, fy1, fz1, t);
  const __m256 n111 = Grad3V(HashV(_mm256_xor_si256(k11, xp1)), fx1, fy1, fz1, t);
  const __m256 a = LerpV(LerpV(n000, n100, u), LerpV(n010, n110, u), v);
  const __m256 b = LerpV(LerpV(n001, n101, u), LerpV(n011, n111, u), v);
  return _mm256_mul_ps(LerpV(a, b, w), _mm256_set1_ps(kScale3));
}

// Each returns the first index it did not do (the scalar tail does the rest).
SYLVA_AVX2 size_t Noise2RowAvx2(uint32_t key, float x0, float dx, float y, float f, size_t n,
                                float* out) {
  const __m256i k = _mm256_set1_epi32(int32_t(key));
  const __m256 gx = _mm256_loadu_ps(kGrad2X), gy = _mm256_loadu_ps(kGrad2Y);
  const __m256 vx0 = _mm256_set1_ps(x0), vdx = _mm256_set1_ps(dx), vf = _mm256_set1_ps(f);
  const __m256 vy = _mm256_mul_ps(_mm256_set1_ps(y), vf);
  __m256i idx = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i step = _mm256_set1_epi32(8);
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 x = _mm256_add_ps(vx0, _mm256_mul_ps(_mm256_cvtepi32_ps(idx), vdx));
    _mm256_storeu_ps(out + i, Noise2V(k, _mm256_mul_ps(x, vf), vy, gx, gy));
    idx = _mm256_add_epi32(idx, step);
  }
  return i;
}

SYLVA_AVX2 size_t Noise2PointsAvx2(uint32_t key, const float* x, const float* y, float f, size_t n,
                                   float* out) {
  const __m256i k = _mm256_set1_epi32(int32_t(key));
  const __m256 gx = _mm256_loadu_ps(kGrad2X), gy = _mm256_loadu_ps(kGrad2Y);
  const __m256 vf = _mm256_set1_ps(f);
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 px = _mm256_mul_ps(_mm256_loadu_ps(x + i), vf);
    const __m256 py = _mm256_mul_ps(_mm256_loadu_ps(y + i), vf);
    _mm256_storeu_ps(out + i, Noise2V(k, px, py, gx, gy));
  }
  return i;
}

SYLVA_AVX2 size_t Noise3PointsAvx2(uint32_t key, const float* x, const float* y, const float* z,
                                   float f, size_t n, float* out) {
  const __m256i k = _mm256_set1_epi32(int32_t(key));
  const Tables3 t{_mm256_loadu_ps(kGrad3X), _mm256_loadu_ps(kGrad3X + 8),
                  _mm256_loadu_ps(kGrad3Y), _mm256_loadu_ps(kGrad3Y + 8),
                  _mm256_loadu_ps(kGrad3Z), _mm256_loadu_ps(kGrad3Z + 8)};
  const __m256 vf = _mm256_set1_ps(f);
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 px = _mm256_mul_ps(_mm256_loadu_ps(x + i), vf);
    const __m256 py = _mm256_mul_ps(_mm256_loadu_ps(y + i), vf);
    const __m256 pz = _mm256_mul_ps(_mm256_loadu_ps(z + i), vf);
    _mm256_storeu_ps(out + i, Noise3V(k, px, py, pz, t));
  }
  return i;
}

}  // namespace

void Noise2Row(Kernel kernel, uint32_t key, float x0, float dx, float y, float f, size_t n,
               float* out) {
  size_t i = kernel == Kernel::kAvx2 ? Noise2RowAvx2(key, x0, dx, y, f, n, out) : 0;
  const float yf = y * f;
  for (; i < n; ++i) out[i] = Noise2(key, (x0 + float(int32_t(i)) * dx) * f, yf);
}

void Noise2Points(Kernel kernel, uint32_t key, const float* x, const float* y, float f, size_t n,
                  float* out) {
  size_t i = kernel == Kernel::kAvx2 ? Noise2PointsAvx2(key, x, y, f, n, out) : 0;
  for (; i < n; ++i) out[i] = Noise2(key, x[i] * f, y[i] * f);
}

void Noise3Points(Kernel kernel, uint32_t key, const float* x, const float* y, const float* z,
                  float f, size_t n, float* out) {
  size_t i = kernel == Kernel::kAvx2 ? Noise3PointsAvx2(key, x, y, z, f, n, out) : 0;
  for (; i < n; ++i) out[i] = Noise3(key, x[i] * f, y[i] * f, z[i] * f);
}

}  // namespace sylva::terrain::kernels
