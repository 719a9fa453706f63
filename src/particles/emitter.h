// Emitters: particles born at a rate or in bursts, with position, velocity
// and lifetime distributions, and colour and size over age. Draws come from
// the counter-based generator keyed by (seed, emitter, particle id), so a
// run is the same on every machine. Dead particles (age >= lifetime) are
// removed without reordering the living ones, whose ids never change.
#pragma once

#include "particles/system.h"

namespace sylva::particles {

// What an emitter makes. Ranges (Validate rejects anything outside, NaN
// included, naming the field and the value):
struct EmitterDef {
  double rate = 100;          // particles per second, 0..1e9 (0: bursts only)
  Vec3 position{0, 0, 0};     // m, each component within +-1e12
  double positionRadius = 0;  // m, 0..1e6: uniform in a ball of this radius
  Vec3 velocity{0, 1, 0};     // m/s, each component within +-1e12
  double velocitySpread = 0;  // m/s, 0..1e6: plus a uniform vector in a ball of this radius
  double lifetime = 2;        // s, 1e-9..1e300: uniform in [lifetime - jitter, lifetime + jitter]
  double lifetimeJitter = 0;  // s, 0..lifetime
  double mass = 1;            // kg, 0..1e30 (0: immovable)
  Vec3f colorStart{1, 1, 1},
      colorEnd{1, 1, 1};  // linear RGB, each 0..1e6; linear in age / lifetime
  float radiusStart = 0.05f, radiusEnd = 0.05f;  // drawn size, m, 0..1e6; linear in age / lifetime
  uint64_t seed = 1;
  uint32_t stream = 0;  // tells emitters with one seed apart
};

// The first field of `def` outside its range, or ok.
Status Validate(const EmitterDef& def);

class Emitter {
 public:
  // An emitter of a valid definition, or the Diagnostic of Validate.
  static Expected<Emitter> Create(const EmitterDef& def);
  // Emits the particles due over the next h seconds (the fractional part
  // carries over, so the count after time T is floor(rate T)); s.size()
  // tells how many. h in 0..1e6 s and rate h below 2^31 particles, else a
  // Diagnostic (naming h or the count) and nothing is emitted.
  [[nodiscard]] Status Emit(ParticleState& s, double h);
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
  explicit Emitter(const EmitterDef& def) : def_(def) {}
  void Spawn(ParticleState& s);
  EmitterDef def_;
  double carry_ = 0;
};

// Removes particles whose age has reached their lifetime, keeping the order
// (and ids) of the living. Returns the number removed.
size_t RemoveDead(ParticleState& s);

}  // namespace sylva::particles
