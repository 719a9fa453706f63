#include "particles/emitter.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace sylva::particles {

static Vec3 InBall(RandomStream& r) {
  for (;;) {  // rejection sampling: exact and uniform
    const Vec3 p(2 * r.Uniform() - 1, 2 * r.Uniform() - 1, 2 * r.Uniform() - 1);
    if (p.squaredNorm() <= 1) return p;
  }
}

void Emitter::Spawn(ParticleState& s) {
  RandomStream r{def_.seed, 0x5e7f00d, def_.stream, s.nextId, 0};
  const Vec3 p = def_.position + def_.positionRadius * InBall(r);
  const Vec3 v = def_.velocity + def_.velocitySpread * InBall(r);
  const double life = std::max(1e-9, def_.lifetime + def_.lifetimeJitter * (2 * r.Uniform() - 1));
  s.Add(p, v, def_.mass, life);
  s.color.back() = def_.colorStart;
  s.radius.back() = def_.radiusStart;
}

int Emitter::Emit(ParticleState& s, double h) {
  carry_ += def_.rate * h;
  const int n = int(std::floor(carry_ + 1e-9));
  carry_ -= n;
  for (int i = 0; i < n; ++i) Spawn(s);
  return n;
}

void Emitter::Burst(ParticleState& s, int n) {
  for (int i = 0; i < n; ++i) Spawn(s);
}

Vec3f Emitter::ColorAt(double age, double lifetime) const {
  const float t = float(std::clamp(lifetime > 0 ? age / lifetime : 1.0, 0.0, 1.0));
  return def_.colorStart * (1 - t) + def_.colorEnd * t;
}

float Emitter::RadiusAt(double age, double lifetime) const {
  const float t = float(std::clamp(lifetime > 0 ? age / lifetime : 1.0, 0.0, 1.0));
  return def_.radiusStart * (1 - t) + def_.radiusEnd * t;
}

void Emitter::Age(ParticleState& s, size_t begin, size_t end) const {
  for (size_t i = begin; i < end && i < s.size(); ++i) {
    s.color[i] = ColorAt(s.age[i], s.lifetime[i]);
    s.radius[i] = RadiusAt(s.age[i], s.lifetime[i]);
  }
}

size_t RemoveDead(ParticleState& s) {
  size_t w = 0;
  const size_t n = s.size();
  for (size_t i = 0; i < n; ++i) {
    if (s.age[i] >= s.lifetime[i]) continue;
    if (w != i) {
      s.position[w] = s.position[i];
      s.velocity[w] = s.velocity[i];
      s.mass[w] = s.mass[i];
      s.invMass[w] = s.invMass[i];
      s.age[w] = s.age[i];
      s.lifetime[w] = s.lifetime[i];
      s.color[w] = s.color[i];
      s.radius[w] = s.radius[i];
      s.id[w] = s.id[i];
    }
    ++w;
  }
  s.position.resize(w);
  s.velocity.resize(w);
  s.mass.resize(w);
  s.invMass.resize(w);
  s.age.resize(w);
  s.lifetime.resize(w);
  s.color.resize(w);
  s.radius.resize(w);
  s.id.resize(w);
  return n - w;
}

}  // namespace sylva::particles
