// Emitters: particles born at a rate or in bursts, with position, velocity
// and lifetime distributions, and colour and size over age. Draws come from
// the counter-based generator keyed by (seed, emitter, particle id), so a
// run is the same on every machine. Dead particles (age >= lifetime) are
// removed without reordering the living ones, whose ids never change.
#pragma once

#include "particles/system.h"

namespace sylva::particles {

struct EmitterDef {
  double rate = 100;  // particles per second (0: bursts only)
  Vec3 position{0, 0, 0};
  double positionRadius = 0;  // uniform in a ball of this radius
  Vec3 velocity{0, 1, 0};
  double velocitySpread = 0;  // plus a uniform vector in a ball of this radius
  double lifetime = 2;        // seconds, uniform in [lifetime - jitter, lifetime + jitter]
  double lifetimeJitter = 0;
  double mass = 1;
  Vec3f colorStart{1, 1, 1}, colorEnd{1, 1, 1};  // linear in age / lifetime
  float radiusStart = 0.05f, radiusEnd = 0.05f;  // drawn size, linear in age / lifetime
  uint64_t seed = 1;
  uint32_t stream = 0;  // tells emitters with one seed apart
};

class Emitter {
 public:
  explicit Emitter(const EmitterDef& def) : def_(def) {}
  // Emits the particles due over the next h seconds (the fractional part
  // carries over, so the count after time T is floor(rate T)). Returns the
  // number emitted.
  int Emit(ParticleState& s, double h);
  // Emits n particles at once (a firework's burst).
  void Burst(ParticleState& s, int n);
  // Colour of a particle of this emitter at the given age.
  Vec3f ColorAt(double age, double lifetime) const;
  float RadiusAt(double age, double lifetime) const;
  // Sets colour and radius over age for particles [begin, end) (this
  // emitter's, as the caller knows them).
  void Age(ParticleState& s, size_t begin, size_t end) const;
  const EmitterDef& def() const { return def_; }

 private:
  void Spawn(ParticleState& s);
  EmitterDef def_;
  double carry_ = 0;
};

// Removes particles whose age has reached their lifetime, keeping the order
// (and ids) of the living. Returns the number removed.
size_t RemoveDead(ParticleState& s);

}  // namespace sylva::particles
