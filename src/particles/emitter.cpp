#include "particles/emitter.h"

#include <algorithm>
#include <cmath>

#include "particles/def_check.h"
#include "particles/particle_core.h"

namespace sylva::particles {

static Vec3 InBall(RandomStream& r) {
  for (;;) {  // rejection sampling: exact and uniform
    const Vec3 p(2 * r.Uniform() - 1, 2 * r.Uniform() - 1, 2 * r.Uniform() - 1);
    if (p.squaredNorm() <= 1) return p;
  }
}

// An orthonormal frame (t, b) perpendicular to the unit vector a.
static void Frame(const Vec3& a, Vec3* t, Vec3* b) {
  *t = std::abs(a.x()) < 0.9 ? a.cross(Vec3::UnitX()).normalized()
                             : a.cross(Vec3::UnitY()).normalized();
  *b = a.cross(*t);
}

// Uniform over the cap cos(angle to a) >= cosMax: the cosine is uniform
// (Archimedes), the turn about a too.
static Vec3 OnCap(const Vec3& a, const Vec3& t, const Vec3& b, double cosMax, double u1,
                  double u2) {
  const double c = 1 - u1 * (1 - cosMax), s = std::sqrt(std::max(0.0, 1 - c * c));
  const double phi = 2 * kPi * u2;
  return c * a + s * (std::cos(phi) * t + std::sin(phi) * b);
}

Vec3 InCone(const Vec3& axis, double spreadDegrees, double u1, double u2) {
  const Vec3 a = axis.normalized();
  Vec3 t, b;
  Frame(a, &t, &b);
  return OnCap(a, t, b, std::cos(spreadDegrees * kDegToRad), u1, u2);
}

// The mesh's triangles checked, and their areas summed (the prefix sums
// that a uniform pick searches).
static Expected<std::vector<double>> CumulativeArea(const EmitterMesh& m) {
  using namespace check;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    if (Status st =
            Finite("EmitterDef.mesh position " + std::to_string(i), m.positions[i], 1e12, "m");
        !st.ok())
      return st.error();
  }
  std::vector<double> sum;
  sum.reserve(m.triangles.size());
  double total = 0;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    for (uint32_t k : m.triangles[t]) {
      if (k >= m.positions.size()) {
        return Error("EmitterDef.mesh triangle " + std::to_string(t) + " has index " +
                     std::to_string(k) + ", but the mesh has " +
                     std::to_string(m.positions.size()) + " positions");
      }
    }
    const Vec3 &a = m.positions[m.triangles[t][0]], &b = m.positions[m.triangles[t][1]],
               &c = m.positions[m.triangles[t][2]];
    total += 0.5 * (b - a).cross(c - a).norm();
    sum.push_back(total);
  }
  if (!(total > 0) || !std::isfinite(total)) {
    return Error("EmitterDef.mesh has total area " + Num(total) + " m^2 over " +
                 std::to_string(m.triangles.size()) +
                 " triangles: a surface to emit from needs an area above 0");
  }
  return sum;
}

Status Validate(const EmitterDef& d) {
  using namespace check;
  SYLVA_CHECK_OK(Range("EmitterDef.rate", d.rate, 0, 1e9, "particles/s"));
  SYLVA_CHECK_OK(Finite("EmitterDef.position", d.position, 1e12, "m"));
  for (int k = 0; k < 3; ++k) {
    if (!(d.size[k] >= 0 && d.size[k] <= 1e6)) {
      return Error("EmitterDef.size " + Vec(d.size) + " has a component outside 0..1e+06 m");
    }
  }
  if (d.shape == EmitterShape::kMesh) {
    if (!d.mesh) return Error("EmitterDef.mesh is empty, and the shape is kMesh");
    if (auto sum = CumulativeArea(*d.mesh); !sum) return sum.error();
  }
  if (d.shape == EmitterShape::kFunction && !d.place) {
    return Error("EmitterDef.place is empty, and the shape is kFunction");
  }
  SYLVA_CHECK_OK(Range("EmitterDef.positionRadius", d.positionRadius, 0, 1e6, "m"));
  SYLVA_CHECK_OK(Finite("EmitterDef.velocity", d.velocity, 1e12, "m/s"));
  SYLVA_CHECK_OK(Range("EmitterDef.spreadDegrees", d.spreadDegrees, 0, 180, "degrees"));
  SYLVA_CHECK_OK(Range("EmitterDef.velocitySpread", d.velocitySpread, 0, 1e6, "m/s"));
  SYLVA_CHECK_OK(Range("EmitterDef.lifetime", d.lifetime, 1e-9, 1e300, "s"));
  SYLVA_CHECK_OK(
      Range("EmitterDef.lifetimeJitter", d.lifetimeJitter, 0, d.lifetime, "s (0..lifetime)"));
  SYLVA_CHECK_OK(Range("EmitterDef.mass", d.mass, 0, 1e30, "kg"));
  if (d.mass == 0)
    return check::Error(
        "EmitterDef.mass: 0 kg; a particle needs a positive mass (pin it with "
        "System::Pin to hold it still)");
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
  if (d.maxAlive == 0) return Error("EmitterDef.maxAlive 0 is outside 1..2^64-1");
  if (d.maxBirths == 0) return Error("EmitterDef.maxBirths 0 is outside 1..2^64-1");
  return {};
}

Expected<Emitter> Emitter::Create(const EmitterDef& def) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  Emitter e(def);
  if (def.shape == EmitterShape::kMesh) {
    auto sum = CumulativeArea(*def.mesh);
    if (!sum) return sum.error();
    // Vose's alias method: scaled areas p_i = n area_i / total; each column
    // keeps p_i of itself (a small one) and lends the rest to a large one.
    const size_t n = sum->size();
    auto table = std::make_shared<AliasTable>();
    table->accept.resize(n);
    table->alias.resize(n);
    std::vector<double> p(n);
    for (size_t i = 0; i < n; ++i)
      p[i] = ((*sum)[i] - (i ? (*sum)[i - 1] : 0)) * double(n) / sum->back();
    std::vector<uint32_t> small, large;
    for (size_t i = 0; i < n; ++i) (p[i] < 1 ? small : large).push_back(uint32_t(i));
    while (!small.empty() && !large.empty()) {
      const uint32_t s = small.back(), l = large.back();
      small.pop_back();
      table->accept[s] = p[s];
      table->alias[s] = l;
      p[l] -= 1 - p[s];
      if (p[l] < 1) {
        large.pop_back();
        small.push_back(l);
      }
    }
    for (uint32_t i : large) table->accept[i] = 1, table->alias[i] = i;
    for (uint32_t i : small) table->accept[i] = 1, table->alias[i] = i;  // rounding leftovers
    e.triangles_ = std::move(table);
  }
  e.speed_ = def.velocity.norm();
  if (def.spreadDegrees > 0 && e.speed_ > 0) {
    e.coneA_ = def.velocity / e.speed_;
    Frame(e.coneA_, &e.coneT_, &e.coneB_);
    e.coneCosMax_ = std::cos(def.spreadDegrees * kDegToRad);
  }
  return e;
}

Vec3 Emitter::Place(RandomStream& r) const {
  const EmitterDef& d = def_;
  Vec3 x = d.position;
  switch (d.shape) {
    case EmitterShape::kPoint:
      break;
    case EmitterShape::kSphere:
      x += 0.5 * d.size.cwiseProduct(InBall(r));
      break;
    case EmitterShape::kBox: {
      const Vec3 u(r.Uniform() - 0.5, r.Uniform() - 0.5, r.Uniform() - 0.5);
      x += u.cwiseProduct(d.size);
      break;
    }
    case EmitterShape::kDisc: {
      const double rad = 0.5 * d.size.x() * std::sqrt(r.Uniform()), phi = 2 * kPi * r.Uniform();
      x += Vec3(rad * std::cos(phi), 0, rad * std::sin(phi));
      break;
    }
    case EmitterShape::kMesh: {
      // A triangle by area (the alias table), then a point uniform in it
      // (Osada et al. 2002: sqrt of one uniform).
      const AliasTable& table = *triangles_;
      const double pick = r.Uniform() * double(table.accept.size());
      const size_t column = std::min(table.accept.size() - 1, size_t(pick));
      const size_t t = pick - double(column) < table.accept[column] ? column : table.alias[column];
      const auto& tri = d.mesh->triangles[t];
      const double r1 = std::sqrt(r.Uniform()), r2 = r.Uniform();
      x += (1 - r1) * d.mesh->positions[tri[0]] + r1 * (1 - r2) * d.mesh->positions[tri[1]] +
           r1 * r2 * d.mesh->positions[tri[2]];
      break;
    }
    case EmitterShape::kFunction: {
      const Vec3 u(r.Uniform(), r.Uniform(), r.Uniform());
      x = d.place(u);
      break;
    }
  }
  if (d.positionRadius > 0) x += d.positionRadius * InBall(r);
  return x;
}

Birth Emitter::Next() {
  RandomStream r{def_.seed, 0x5e7f00d, def_.stream, births_++, 0};
  const Vec3 x = Place(r);
  Vec3 v = def_.velocity;
  if (def_.spreadDegrees > 0 && speed_ > 0) {
    const double u1 = r.Uniform(), u2 = r.Uniform();
    v = speed_ * OnCap(coneA_, coneT_, coneB_, coneCosMax_, u1, u2);
  }
  if (def_.velocitySpread > 0) v += def_.velocitySpread * InBall(r);
  const double life = std::max(1e-9, def_.lifetime + def_.lifetimeJitter * (2 * r.Uniform() - 1));
  return Birth{x, v, life};
}

uint64_t Emitter::Allowed(const ParticleState& s, uint64_t n) {
  const uint64_t room = s.size() >= def_.maxAlive ? 0 : def_.maxAlive - s.size();
  const uint64_t left = def_.maxBirths - made_;
  const uint64_t ok = std::min({n, room, left});
  dropped_ += n - ok;
  made_ += ok;
  return ok;
}

void Emitter::Add(ParticleState& s, const Birth& b, double age,
                  std::span<const Collider> colliders) {
  Vec3 at = b.position + b.velocity * age;
  if (age > 0 && at != b.position) {
    Contact contact;
    for (const Collider& c : colliders) {
      if (c.Intersect(b.position, at, &contact, def_.radiusStart)) {
        at = b.position;
        break;
      }
    }
  }
  s.Add(at, b.velocity, def_.mass, b.lifetime);
  s.age.back() = age;
  s.color.back() = def_.colorStart;
  s.radius.back() = def_.radiusStart;
}

// Room for n more in every array a birth appends to (geometric, so a
// stream of small calls stays linear).
static void Reserve(ParticleState& s, uint64_t n) {
  const size_t want = s.size() + size_t(n);
  if (want <= s.position.capacity()) return;
  const size_t cap = std::max(want, 2 * s.position.capacity());
  s.position.reserve(cap);
  s.velocity.reserve(cap);
  s.mass.reserve(cap);
  s.invMass.reserve(cap);
  s.age.reserve(cap);
  s.lifetime.reserve(cap);
  s.color.reserve(cap);
  s.radius.reserve(cap);
  s.id.reserve(cap);
}

Status Emitter::Emit(ParticleState& s, double h, std::span<const Collider> colliders) {
  using namespace check;
  SYLVA_CHECK_OK(Range("Emitter.Emit h", h, 0, 1e6, "s"));
  const double due = carry_ + def_.rate * h;
  if (!(due < 2147483647.0)) {
    return Error("Emitter.Emit: rate " + Num(def_.rate) + " particles/s for h " + Num(h) +
                 " s is " + Num(due) + " particles due, 2^31 - 1 or more in one call");
  }
  const uint64_t n = uint64_t(std::floor(due + 1e-9));
  // Birth j of this call comes when the running count reaches the next
  // whole particle: (j + 1 - carry) / rate after the interval's start.
  const double start = carry_;
  carry_ = std::max(0.0, due - double(n));
  const uint64_t ok = Allowed(s, n);
  Reserve(s, ok);
  for (uint64_t j = 0; j < ok; ++j) {
    // (Never a division by a zero interval: floor(due + 1e-9) leaves a
    // carry below 1 - 1e-9, so h = 0 brings no birth; guarded all the same.)
    const double span = def_.rate * h;
    const double f = span > 0 ? std::clamp((double(j) + 1 - start) / span, 0.0, 1.0) : 1.0;
    Add(s, Next(), (1 - f) * h, colliders);
  }
  return {};
}

uint64_t Emitter::Burst(ParticleState& s, uint64_t n) {
  const uint64_t ok = Allowed(s, n);
  Reserve(s, ok);
  for (uint64_t j = 0; j < ok; ++j) Add(s, Next(), 0, {});
  return ok;
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
  return RemoveIf(
      s.size(), [&](size_t i) { return s.age[i] >= s.lifetime[i]; }, nullptr, s.position,
      s.velocity, s.mass, s.invMass, s.age, s.lifetime, s.color, s.radius, s.id);
}

}  // namespace sylva::particles
