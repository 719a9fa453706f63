// More forces: random drift, a divergence-free noise wind, a force field
// sampled on a grid, and penalty (soft) constraints.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "particles/system.h"

namespace sylva::particles {

// Random drift: a Gaussian force of standard deviation `sigma` newtons per
// axis, drawn afresh every step from the counter-based generator keyed by
// (seed, particle id, step), so it is the same whatever the thread count or
// the integrator's stages (all stages of a step see one draw).
// sigma 0..1e12 N (Check, on every step, says otherwise).
class RandomDrift : public LocalForce {
 public:
  RandomDrift(double sigma, uint64_t seed) : sigma_(sigma), seed_(seed) {}
  Status Check(const ParticleState& s) const override;
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override;

 private:
  double sigma_;
  uint64_t seed_;
};

// Curl-noise wind (Bridson, Hourihan & Nordenstam, "Curl-noise for
// procedural fluid flow", SIGGRAPH 2007). The potential is a sum of random
// Fourier modes, psi(x, t) = sum_j a_j sin(k_j . x + w_j t + phi_j), whose
// curl u = sum_j (k_j x a_j) cos(k_j . x + w_j t + phi_j) is divergence-free
// exactly (k . (k x a) = 0), smooth, and tileless. Wavelengths are drawn
// around `scale`; the field's RMS speed is `speed`; `mean` is added.
// The force pulls each particle's velocity toward the wind: f = drag (u - v).
// Ranges (Validate rejects anything outside, NaN included):
struct NoiseWindDef {
  Vec3 mean{0, 0, 0};    // m/s, each component within +-1e12
  double speed = 1;      // RMS of the fluctuation, m/s, 0..1e6
  double scale = 1;      // typical eddy size, m, 1e-9..1e12
  double frequency = 0;  // how fast the pattern changes, rad/s, 0..1e9
  double drag = 1;       // N per (m/s) of relative speed, 0..1e12
  int modes = 16;        // 1..65536
  uint64_t seed = 1;
};

// The first field of `def` outside its range, or ok.
Status Validate(const NoiseWindDef& def);

class NoiseWind : public LocalForce {
 public:
  // A wind of a valid definition, or the Diagnostic of Validate.
  static Expected<std::shared_ptr<NoiseWind>> Create(const NoiseWindDef& def);
  Vec3 Velocity(const Vec3& x, double t) const;
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override;
  void AddJacobianProduct(const ParticleState& s, const Vec3* x, const Vec3* v, double cx,
                          double cv, const Vec3* p, Vec3* y) const override;

 private:
  explicit NoiseWind(const NoiseWindDef& def);
  struct Mode {
    Vec3 k, curlAmp;  // k and k x a
    double omega, phase;
  };
  NoiseWindDef def_;
  std::vector<Mode> modes_;
};

// An acceleration field (m/s^2, so f = m a) sampled on a regular grid of
// nx x ny x nz points spanning [lo, hi], interpolated trilinearly. Outside
// the box the field is zero, or the nearest border value with `clamp`.
// Create checks n (each 2..4096), samples (n0 n1 n2 of them, each
// component within +-1e12 m/s^2) and the box (finite, lo < hi in every
// axis).
class FieldGrid : public LocalForce {
 public:
  static Expected<std::shared_ptr<FieldGrid>> Create(const Vec3& lo, const Vec3& hi,
                                                     std::array<int, 3> n,
                                                     std::vector<Vec3> samples, bool clamp = false);
  Vec3 At(const Vec3& x) const;
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override;

 private:
  FieldGrid(const Vec3& lo, const Vec3& hi, std::array<int, 3> n, std::vector<Vec3> samples,
            bool clamp);
  Vec3 lo_, hi_, inv_;
  std::array<int, 3> n_;
  std::vector<Vec3> samples_;  // x fastest
  bool clamp_;
};

// Penalty constraints (Witkin, "Constrained dynamics", SIGGRAPH course
// notes): a behaviour C(x) = 0 turned into the energy E = ks C^2 / 2, whose
// force is f = -(ks C + kd dC/dt) grad C. Kinds:
//   anchor      particle i near a fixed point: C = |x_i - p|
//   distance    particles i, j at distance d:  C = |x_i - x_j| - d
//   plane       particle i on a plane:         C = n . (x_i - p)
//   sphere      particle i on a sphere:        C = |x_i - c| - r
class Penalty : public Force {
 public:
  void Anchor(uint32_t i, const Vec3& point, double ks, double kd);
  void Distance(uint32_t i, uint32_t j, double distance, double ks, double kd);
  void OnPlane(uint32_t i, const Vec3& point, const Vec3& normal, double ks, double kd);
  void OnSphere(uint32_t i, const Vec3& centre, double radius, double ks, double kd);
  // Every particle index named is below s.size() (System::Step asks).
  Status Check(const ParticleState& s) const override;
  // Follows System::RemoveDead: terms follow their particles; a term that
  // names a removed particle goes.
  void Renumber(const std::vector<uint32_t>& newIndex) override;
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;
  // The implicit solver's Jacobian, for anchors and distances (the stiff
  // ones); plane and sphere terms are treated explicitly.
  void AddJacobianProduct(const ParticleState& s, const Vec3* x, const Vec3* v, double cx,
                          double cv, const Vec3* p, Vec3* y) const override;
  // Total penalty energy sum ks C^2 / 2 at positions x.
  double Energy(const Vec3* x) const;

 private:
  enum class Kind { kAnchor, kDistance, kPlane, kSphere };
  struct Term {
    Kind kind;
    uint32_t i, j;
    Vec3 point, normal;
    double value, ks, kd;
  };
  std::vector<Term> terms_;
  uint32_t maxIndex_ = 0;
};

}  // namespace sylva::particles
