// The gradient-noise kernels, internal to the terrain library: the scalar
// sample functions (inline, shared by the point calls and the fractal
// sums) and the row kernels, each with an AVX2 twin in noise_kernels.cpp
// that runs the same operations in the same order on eight samples.
//
// A sample at (x, y):
//   fl = floor(x), ix = int32(fl), fx = x - fl   (same for y)
//   u = fade(fx) = ((fx fx) fx) (fx (6 fx - 15) + 10)
//   corner hash h = ((key ^ ix PX ^ iy PY) M1; h ^= h >> 15; h *= M2)
//   corner value = gx[h >> 29] dx + gy[h >> 29] dy   (dx, dy: offset to the point)
//   value = lerp(lerp(n00, n10, u), lerp(n01, n11, u), v) * scale,
//   lerp(a, b, t) = a + t (b - a).
// int32(fl) is the x86 conversion: NaN or out of range gives INT32_MIN.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "terrain/noise.h"

namespace sylva::terrain::kernels {

inline constexpr uint32_t kPrimeX = 501125321u;
inline constexpr uint32_t kPrimeY = 1136930381u;
inline constexpr uint32_t kPrimeZ = 1720413743u;
inline constexpr uint32_t kMul1 = 0x27d4eb2du;
inline constexpr uint32_t kMul2 = 0x85ebca6bu;
inline constexpr float kScale2 = 1.5f;
inline constexpr float kScale3 = 0.96f;

// Unit gradients at 22.5 + 45k degrees.
inline constexpr float kGrad2X[8] = {0.92387953f,  0.38268343f,  -0.38268343f, -0.92387953f,
                                     -0.92387953f, -0.38268343f, 0.38268343f,  0.92387953f};
inline constexpr float kGrad2Y[8] = {0.38268343f,  0.92387953f,  0.92387953f,  0.38268343f,
                                     -0.38268343f, -0.92387953f, -0.92387953f, -0.38268343f};
// Perlin's 12 cube edges and his 4 repeats.
inline constexpr float kGrad3X[16] = {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, -1, 0, 0};
inline constexpr float kGrad3Y[16] = {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, 1, -1, -1};
inline constexpr float kGrad3Z[16] = {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 0, 1, -1};

// The 32-bit key a 64-bit seed hashes to (SplitMix64's finaliser).
inline uint32_t KeyOf(uint64_t seed) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return uint32_t((z ^ (z >> 31)) >> 32);
}

// cvttps2dq: truncation, INT32_MIN for NaN and out of range.
inline uint32_t ToLattice(float f) {
  return (f >= -2147483648.0f && f < 2147483648.0f) ? uint32_t(int32_t(f)) : 0x80000000u;
}

inline uint32_t Hash(uint32_t k) {
  k *= kMul1;
  k ^= k >> 15;
  return k * kMul2;
}

inline float Fade(float t) {
  return ((t * t) * t) * (t * (t * 6.0f - 15.0f) + 10.0f);
}
inline float Lerp(float a, float b, float t) {
  return a + t * (b - a);
}

inline float Grad2(uint32_t h, float dx, float dy) {
  const uint32_t g = h >> 29;
  return kGrad2X[g] * dx + kGrad2Y[g] * dy;
}

inline float Grad3(uint32_t h, float dx, float dy, float dz) {
  const uint32_t g = h >> 28;
  return (kGrad3X[g] * dx + kGrad3Y[g] * dy) + kGrad3Z[g] * dz;
}

inline float Noise2(uint32_t key, float x, float y) {
  const float flx = std::floor(x), fly = std::floor(y);
  const uint32_t xp0 = ToLattice(flx) * kPrimeX, yp0 = ToLattice(fly) * kPrimeY;
  const uint32_t xp1 = xp0 + kPrimeX, yp1 = yp0 + kPrimeY;
  const float fx = x - flx, fy = y - fly;
  const float fx1 = fx - 1.0f, fy1 = fy - 1.0f;
  const float u = Fade(fx), v = Fade(fy);
  const float n00 = Grad2(Hash(key ^ xp0 ^ yp0), fx, fy);
  const float n10 = Grad2(Hash(key ^ xp1 ^ yp0), fx1, fy);
  const float n01 = Grad2(Hash(key ^ xp0 ^ yp1), fx, fy1);
  const float n11 = Grad2(Hash(key ^ xp1 ^ yp1), fx1, fy1);
  return Lerp(Lerp(n00, n10, u), Lerp(n01, n11, u), v) * kScale2;
}

inline float Noise3(uint32_t key, float x, float y, float z) {
  const float flx = std::floor(x), fly = std::floor(y), flz = std::floor(z);
  const uint32_t xp0 = ToLattice(flx) * kPrimeX, yp0 = ToLattice(fly) * kPrimeY;
  const uint32_t zp0 = ToLattice(flz) * kPrimeZ;
  const uint32_t xp1 = xp0 + kPrimeX, yp1 = yp0 + kPrimeY, zp1 = zp0 + kPrimeZ;
  const float fx = x - flx, fy = y - fly, fz = z - flz;
  const float fx1 = fx - 1.0f, fy1 = fy - 1.0f, fz1 = fz - 1.0f;
  const float u = Fade(fx), v = Fade(fy), w = Fade(fz);
  const float n000 = Grad3(Hash(key ^ xp0 ^ yp0 ^ zp0), fx, fy, fz);
  const float n100 = Grad3(Hash(key ^ xp1 ^ yp0 ^ zp0), fx1, fy, fz);
  const float n010 = Grad3(Hash(key ^ xp0 ^ yp1 ^ zp0), fx, fy1, fz);
  const float n110 = Grad3(Hash(key ^ xp1 ^ yp1 ^ zp0), fx1, fy1, fz);
  const float n001 = Grad3(Hash(key ^ xp0 ^ yp0 ^ zp1), fx, fy, fz1);
  const float n101 = Grad3(Hash(key ^ xp1 ^ yp0 ^ zp1), fx1, fy, fz1);
  const float n011 = Grad3(Hash(key ^ xp0 ^ yp1 ^ zp1), fx, fy1, fz1);
  const float n111 = Grad3(Hash(key ^ xp1 ^ yp1 ^ zp1), fx1, fy1, fz1);
  const float a = Lerp(Lerp(n000, n100, u), Lerp(n010, n110, u), v);
  const float b = Lerp(Lerp(n001, n101, u), Lerp(n011, n111, u), v);
  return Lerp(a, b, w) * kScale3;
}

// out[i] = Noise2(key, (x0 + float(i) dx) f, y f) for i in [0, n).
void Noise2Row(Kernel kernel, uint32_t key, float x0, float dx, float y, float f, size_t n,
               float* out);
// out[i] = Noise2(key, x[i] f, y[i] f).
void Noise2Points(Kernel kernel, uint32_t key, const float* x, const float* y, float f, size_t n,
                  float* out);
// out[i] = Noise3(key, x[i] f, y[i] f, z[i] f).
void Noise3Points(Kernel kernel, uint32_t key, const float* x, const float* y, const float* z,
                  float f, size_t n, float* out);

}  // namespace sylva::terrain::kernels
