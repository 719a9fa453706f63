// Counter-based random numbers.
//
// A draw is a pure function of (seed, stream, a, b, k): no generator state
// is carried from one module to the next, so the numbers a derivation sees
// do not depend on thread count, chunking or evaluation order. The lsys
// deriver keys draws by (seed, purpose, step, module index, draw number).
//
// The mixer is SplitMix64's finaliser (Steele, Lea & Flood 2014, "Fast
// splittable pseudorandom number generators") applied in a chain; each
// input word is folded in with a distinct odd constant. It passes the
// statistical checks our tests make (uniform moments, chi-square of
// stochastic production frequencies).
#pragma once

#include <cmath>
#include <cstdint>

namespace sylva {

constexpr uint64_t Mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Hash of up to five 64-bit words.
constexpr uint64_t CounterHash(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0,
                               uint64_t d = 0) {
  uint64_t h = Mix64(seed + 0x9e3779b97f4a7c15ULL);
  h = Mix64(h ^ (a + 0x632be59bd9b4e019ULL));
  h = Mix64(h ^ (b + 0x8cb92ba72f3d8dd7ULL));
  h = Mix64(h ^ (c + 0xd6e8feb86659fd93ULL));
  return Mix64(h ^ (d + 0xa0761d6478bd642fULL));
}

// Uniform double in [0, 1) from the top 53 bits.
constexpr double ToUnit(uint64_t bits) {
  return double(bits >> 11) * 0x1.0p-53;
}

// A stream of draws with a fixed key; Next() advances only a local counter.
struct RandomStream {
  uint64_t seed = 1;
  uint64_t a = 0, b = 0, c = 0;  // e.g. purpose, step, module index
  uint64_t counter = 0;

  double Uniform() { return ToUnit(CounterHash(seed, a, b, c, counter++)); }
  // Standard normal by Box-Muller; uses two draws.
  double Normal() {
    double u1 = Uniform(), u2 = Uniform();
    if (u1 < 0x1.0p-60) u1 = 0x1.0p-60;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
  }
};

}  // namespace sylva
