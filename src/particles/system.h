// Newtonian particles (Angel & Shreiner ch. 9; Baraff & Witkin, "Physically
// Based Modeling", SIGGRAPH course notes).
//
// State is structure of arrays, hot fields apart from cold ones:
//   hot   position, velocity            (48 bytes a particle)
//   cold  mass, inverse mass, age, lifetime, colour, id
// Each step computes every force first, for all particles (into an array of
// accelerations), then advances the state with the chosen integrator, then
// resolves collisions. Forces are evaluated on whatever positions and
// velocities the integrator asks about (RK stages), never on the stored
// state directly.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/math.h"

namespace sylva::particles {

struct ParticleState {
  // hot
  std::vector<Vec3> position, velocity;
  // cold
  std::vector<double> mass, invMass, age, lifetime;
  std::vector<Vec3f> color;
  std::vector<uint32_t> id;
  uint32_t nextId = 0;

  size_t size() const { return position.size(); }
  // Adds a particle; mass 0 or less means immovable (infinite mass).
  uint32_t Add(const Vec3& p, const Vec3& v, double mass = 1, double lifetime = 1e300);
};

// A force adds to f[i] (newtons) for every particle, given positions x and
// velocities v (of size n) and the particles' cold data in `s`.
class Force {
 public:
  virtual ~Force() = default;
  virtual void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const = 0;
};

// Constant acceleration g for every movable particle (f = m g).
class Gravity : public Force {
 public:
  explicit Gravity(const Vec3& g) : g_(g) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;

 private:
  Vec3 g_;
};

// Drag: f = -k1 v - k2 |v| v (linear and quadratic).
class Drag : public Force {
 public:
  Drag(double linear, double quadratic = 0) : k1_(linear), k2_(quadratic) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;

 private:
  double k1_, k2_;
};

// Damped Hooke springs between particle pairs (Angel & Shreiner 9.3):
// with d = p_a - p_b, f_a = -[ks(|d| - rest) + kd (d'.d)/|d|] d/|d|, f_b = -f_a.
class Springs : public Force {
 public:
  struct Spring {
    uint32_t a, b;
    double rest, ks, kd;
  };
  void Add(uint32_t a, uint32_t b, double rest, double ks, double kd) { springs_.push_back({a, b, rest, ks, kd}); }
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;
  const std::vector<Spring>& springs() const { return springs_; }

 private:
  std::vector<Spring> springs_;
};

// A user force as a callable.
class ForceFunction : public Force {
 public:
  using Fn = std::function<void(const ParticleState&, const Vec3*, const Vec3*, Vec3*)>;
  explicit ForceFunction(Fn fn) : fn_(std::move(fn)) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override {
    fn_(s, x, v, f);
  }

 private:
  Fn fn_;
};

enum class Integrator {
  kExplicitEuler,    // x += h v, v += h a(x, v): first order, unstable for stiff springs
  kSymplecticEuler,  // v += h a(x, v), x += h v_new: first order, bounded energy error
  kMidpoint,         // RK2 (improved Euler): second order, two evaluations
  kRK4,              // classical Runge-Kutta: fourth order, four evaluations
};

// A plane collider: the particle stays on the side the normal points to.
// Crossings are exact: the time of contact is found by linear interpolation
// between the step's start and end, the normal velocity is reversed and
// scaled by the restitution, the tangential one scaled by (1 - friction),
// and the particle is placed where its reflected path would be.
struct Plane {
  Vec3 point{0, 0, 0};
  Vec3 normal{0, 1, 0};  // unit
  double restitution = 1;
  double friction = 0;   // 0..1, fraction of tangential speed lost per contact
};

class System {
 public:
  ParticleState state;
  double time = 0;

  void AddForce(std::shared_ptr<Force> f) { forces_.push_back(std::move(f)); }
  void AddPlane(const Plane& p) { planes_.push_back(p); }

  // Accelerations for positions x and velocities v (all particles).
  void Accelerations(const Vec3* x, const Vec3* v, Vec3* a) const;
  // One step of length h: forces, integration, collisions, ageing.
  void Step(double h, Integrator integrator);
  // Kinetic energy, sum of m |v|^2 / 2 over movable particles.
  double KineticEnergy() const;

 private:
  void Collide(const std::vector<Vec3>& x0, const std::vector<Vec3>& v0, double h);
  std::vector<std::shared_ptr<Force>> forces_;
  std::vector<Plane> planes_;
  // Scratch for the integrators (sized once per particle count).
  mutable std::vector<Vec3> f_, k_[8], x_, v_, before_, vbefore_;
};

}  // namespace sylva::particles
