// Emitters: particles born at a rate or in bursts, from a shape (point,
// sphere, box, disc, triangle-mesh surface, or a placement function), with
// velocities in a cone and a ball, jittered lifetimes, and colour and size
// over age.
//
// Births are spread over the step. Emit(s, h) makes the particles born in
// the h seconds that end at the call: at a steady rate r they are born
// 1/r apart in time, the fraction carried from call to call, so birth k of
// the emitter's life is at t_k = (k + 1) / r. A particle born at fraction f
// of the interval is moved on by its velocity for the rest of it,
// (1 - f) h, and starts with that age: a fast emitter leaves an even
// stream, not one clump per step (tested by the spacing of a stream).
//
// Every particle is drawn independently: draws come from the counter-based
// generator keyed by (seed, stream, the emitter's own birth count), never
// by the target's ids, so one emitter emitting into two fresh states makes
// different particles, emitters of different seeds or streams differ, and
// the same definition reproduces the same particles on every machine.
//
// Dead particles (age >= lifetime) are removed by RemoveDead without
// reordering the living ones, whose ids never change.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/rng.h"
#include "particles/system.h"

namespace sylva::particles {

// Where particles are born, about EmitterDef::position.
enum class EmitterShape {
  kPoint,     // at position
  kSphere,    // uniform in the ellipsoid of diameters `size`
  kBox,       // uniform in the box of edges `size`
  kDisc,      // uniform in the horizontal (XZ) disc of diameter size.x
  kMesh,      // uniform over the area of `mesh` (area-weighted triangles), offset by position
  kFunction,  // place(u), u uniform in [0, 1)^3 (terrains, plants: the caller's shape)
};

// A triangle mesh to emit from: its surface, uniform by area.
struct EmitterMesh {
  std::vector<Vec3> positions;                     // m, each component within +-1e12
  std::vector<std::array<uint32_t, 3>> triangles;  // indices into positions
};

// What an emitter makes. Ranges (Validate rejects anything outside, NaN
// included, naming the field and the value):
struct EmitterDef {
  double rate = 100;  // particles per second, 0..1e9 (0: bursts only)
  EmitterShape shape = EmitterShape::kPoint;
  Vec3 position{0, 0, 0};  // m, each component within +-1e12: the shape's centre
  Vec3 size{0, 0, 0};      // m, each component 0..1e6: the shape's full extent (0: a point)
  // kMesh: the surface (total area above 0, indices in range, vertices
  // finite); kFunction: the placement (not empty). Ignored by other shapes.
  std::shared_ptr<const EmitterMesh> mesh;
  std::function<Vec3(const Vec3& u)> place;
  double positionRadius = 0;  // m, 0..1e6: plus a uniform offset in a ball of this radius
  // Velocity: `velocity` turned uniformly within a cone of half-angle
  // spreadDegrees about itself (its length kept), plus a uniform vector in
  // a ball of radius velocitySpread.
  Vec3 velocity{0, 1, 0};     // m/s, each component within +-1e12
  double spreadDegrees = 0;   // degrees, 0..180 (180: any direction)
  double velocitySpread = 0;  // m/s, 0..1e6
  double lifetime = 2;        // s, 1e-9..1e300: uniform in [lifetime - jitter, lifetime + jitter]
  double lifetimeJitter = 0;  // s, 0..lifetime
  double mass = 1;            // kg, (0, 1e30]
  Vec3f colorStart{1, 1, 1},
      colorEnd{1, 1, 1};  // linear RGB, each 0..1e6; linear in age / lifetime
  // Metres, 0..1e6, linear in age / lifetime: the particle's radius (its
  // ball for the colliders, and its drawn size); births take radiusStart.
  float radiusStart = 0.05f, radiusEnd = 0.05f;
  // Limits: Emit and Burst make no particle while the target holds maxAlive
  // or more, nor more than maxBirths over the emitter's life; the births
  // refused are counted (Emitter::dropped). Both at least 1.
  uint64_t maxAlive = std::numeric_limits<uint64_t>::max();
  uint64_t maxBirths = std::numeric_limits<uint64_t>::max();
  uint64_t seed = 1;
  uint32_t stream = 0;  // tells emitters with one seed apart
};

// The first field of `def` outside its range, or ok.
Status Validate(const EmitterDef& def);

// One particle as drawn, before it is added.
struct Birth {
  Vec3 position, velocity;
  double lifetime;
};

class Emitter {
 public:
  // An emitter of a valid definition, or the Diagnostic of Validate.
  static Expected<Emitter> Create(const EmitterDef& def);
  // Emits the particles born over the h seconds that end now (the
  // fractional part carries over, so the count after time T is
  // floor(rate T), less any refused by the limits); s.size() tells how
  // many. Each is moved on by its velocity for its age (no forces), unless
  // that move would cross one of `colliders` (a ball of radiusStart): then
  // it starts where it was born. h in 0..1e6 s and rate h below 2^31
  // particles, else a Diagnostic (naming h or the count) and nothing is
  // emitted.
  [[nodiscard]] Status Emit(ParticleState& s, double h, std::span<const Collider> colliders = {});
  // Emits n particles at once, age 0 (a firework's burst); returns how many
  // the limits let through.
  uint64_t Burst(ParticleState& s, uint64_t n);
  // Draws the next particle without adding it (it counts as a birth for
  // the draws, not for the limits): for callers that place births
  // themselves, such as a burst where another particle dies.
  Birth Next();
  // Colour of a particle of this emitter at the given age.
  Vec3f ColorAt(double age, double lifetime) const;
  float RadiusAt(double age, double lifetime) const;
  // Sets colour and radius over age for particles [begin, end) (this
  // emitter's, as the caller knows them).
  void Age(ParticleState& s, size_t begin, size_t end) const;
  const EmitterDef& def() const { return def_; }
  uint64_t births() const { return births_; }    // particles drawn so far
  uint64_t dropped() const { return dropped_; }  // births refused by the limits

 private:
  explicit Emitter(const EmitterDef& def) : def_(def) {}
  Vec3 Place(RandomStream& r) const;
  // Adds a drawn particle of age `age`, moved on by its velocity for it.
  void Add(ParticleState& s, const Birth& b, double age, std::span<const Collider> colliders);
  // How many of n births the limits let through into s (counting the rest).
  uint64_t Allowed(const ParticleState& s, uint64_t n);
  EmitterDef def_;
  // kMesh: Walker's alias table over the triangles by area (Vose 1991), so
  // a pick is O(1): triangle i = floor(u n) if the rest of u n is below
  // accept[i], else alias[i].
  struct AliasTable {
    std::vector<double> accept;
    std::vector<uint32_t> alias;
  };
  std::shared_ptr<const AliasTable> triangles_;
  // The velocity cone, set up once: unit axis a and a frame t, b about it.
  Vec3 coneA_ = Vec3::UnitY(), coneT_ = Vec3::UnitX(), coneB_ = Vec3::UnitZ();
  double coneCosMax_ = 1, speed_ = 0;
  double carry_ = 0;
  uint64_t births_ = 0, made_ = 0, dropped_ = 0;
};

// A unit vector uniform over the spherical cap of half-angle spreadDegrees
// (0..180) about `axis` (not zero), from two uniforms in [0, 1).
Vec3 InCone(const Vec3& axis, double spreadDegrees, double u1, double u2);

// Removes particles whose age has reached their lifetime, keeping the order
// (and ids) of the living. Returns the number removed. A state with springs
// or penalty forces uses System::RemoveDead, which renumbers them too.
size_t RemoveDead(ParticleState& s);

}  // namespace sylva::particles
