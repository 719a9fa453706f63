#include "particles/emitter.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"
#include "particles/def_check.h"

namespace sylva::particles {

static Vec3 InBall(RandomStream& r) {
  for (;;) {  // rejection sampling: exact and uniform
    const Vec3 p(2 * r.Uniform() - 1, 2 * r.Uniform() - 1, 2 * r.Uniform() - 1);
    if (p.squaredNorm() <= 1) return p;
  }
}

Status Validate(const EmitterDef& d) {
  using namespace check;
  SYLVA_CHECK_OK(Range("EmitterDef.rate", d.rate, 0, 1e9, "particles/s"));
  SYLVA_CHECK_OK(Finite("EmitterDef.position", d.position, 1e12, "m"));
  SYLVA_CHECK_OK(Range("EmitterDef.positionRadius", d.positionRadius, 0, 1e6, "m"));
  SYLVA_CHECK_OK(Finite("EmitterDef.velocity", d.velocity, 1e12, "m/s"));
  SYLVA_CHECK_OK(Range("EmitterDef.velocitySpread", d.velocitySpread, 0, 1e6, "m/s"));
  SYLVA_CHECK_OK(Range("EmitterDef.lifetime", d.lifetime, 1e-9, 1e300, "s"));
  SYLVA_CHECK_OK(
      Range("EmitterDef.lifetimeJitter", d.lifetimeJitter, 0, d.lifetime, "s (0..lifetime)"));
  SYLVA_CHECK_OK(Range("EmitterDef.mass", d.mass, 0, 1e30, "kg"));
  for (const Vec3f* c : {&d.colorStart, &d.colorEnd}) {
    const char* name = c == &d.colorStart ? "EmitterDef.colorStart" : "EmitterDef.colorEnd";
    for (int k = 0; k < 3; ++k) {
      if (!((*c)[k] >= 0 && (*c)[k] <= 1e6)) {
        return Error(std::string(name) + " " + Vec(c->cast<double>()) +
                     " has a component outside 0..1e+06");
      }
    }
  }
  SYLVA_CHECK_OK(Range("EmitterDef.radiusStart", d.radiusStart, 0, 1e6, "m"));
  SYLVA_CHECK_OK(Range("EmitterDef.radiusEnd", d.radiusEnd, 0, 1e6, "m"));
  return {};
}

Expected<Emitter> Emitter::Create(const EmitterDef& def) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  return Emitter(def);
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

Status Emitter::Emit(ParticleState& s, double h) {
  using namespace check;
  SYLVA_CHECK_OK(Range("Emitter.Emit h", h, 0, 1e6, "s"));
  const double due = carry_ + def_.rate * h;
  if (!(due < 2147483647.0)) {
    return Error("Emitter.Emit: rate " + Num(def_.rate) + " particles/s for h " + Num(h) +
                 " s is " + Num(due) + " particles, more than 2^31 - 1 in one call");
  }
  const int n = int(std::floor(due + 1e-9));
  carry_ = due - n;
  for (int i = 0; i < n; ++i) Spawn(s);
  return {};
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
