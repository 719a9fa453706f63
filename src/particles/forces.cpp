#include "particles/forces.h"

#include <algorithm>
#include <cmath>

#include "core/assert.h"
#include "core/rng.h"
#include "particles/def_check.h"

namespace sylva::particles {

void RandomDrift::AccumulateRange(const ParticleState& s, const Vec3*, const Vec3*, Vec3* f,
                                  size_t begin, size_t end) const {
  for (size_t i = begin; i < end; ++i) {
    RandomStream r{seed_, 0xd21f7, s.id[i], s.step, 0};
    const double a = r.Normal(), b = r.Normal(), c = r.Normal();
    f[i - begin] += sigma_ * Vec3(a, b, c);
  }
}

Status Validate(const NoiseWindDef& d) {
  using namespace check;
  SYLVA_CHECK_OK(Finite("NoiseWindDef.mean", d.mean, 1e12, "m/s"));
  SYLVA_CHECK_OK(Range("NoiseWindDef.speed", d.speed, 0, 1e6, "m/s"));
  SYLVA_CHECK_OK(Range("NoiseWindDef.scale", d.scale, 1e-9, 1e12, "m"));
  SYLVA_CHECK_OK(Range("NoiseWindDef.frequency", d.frequency, 0, 1e9, "rad/s"));
  SYLVA_CHECK_OK(Range("NoiseWindDef.drag", d.drag, 0, 1e12, "N s/m"));
  SYLVA_CHECK_OK(Range("NoiseWindDef.modes", d.modes, 1, 65536));
  return {};
}

Expected<std::shared_ptr<NoiseWind>> NoiseWind::Create(const NoiseWindDef& def) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  return std::shared_ptr<NoiseWind>(new NoiseWind(def));
}

NoiseWind::NoiseWind(const NoiseWindDef& def) : def_(def) {
  RandomStream r{def.seed, 0xc0e1, 0, 0, 0};
  const int m = def.modes;
  for (int j = 0; j < m; ++j) {
    // Direction uniform on the sphere, wavenumber around 2 pi / scale.
    Vec3 dir;
    do {
      dir = Vec3(r.Normal(), r.Normal(), r.Normal());
    } while (dir.squaredNorm() < 1e-12);
    dir.normalize();
    const double k = 2 * M_PI / def.scale * (0.5 + r.Uniform());
    Vec3 a(r.Normal(), r.Normal(), r.Normal());
    Mode mode;
    mode.k = k * dir;
    mode.curlAmp = mode.k.cross(a);
    mode.omega = def.frequency * (0.5 + r.Uniform());
    mode.phase = 2 * M_PI * r.Uniform();
    modes_.push_back(mode);
  }
  // Scale the amplitudes so the RMS speed of the fluctuation is def.speed:
  // each mode contributes |k x a|^2 / 2 on average.
  double ms = 0;
  for (const Mode& mode : modes_) ms += 0.5 * mode.curlAmp.squaredNorm();
  const double scale = ms > 0 ? def.speed / std::sqrt(ms) : 0;
  for (Mode& mode : modes_) mode.curlAmp *= scale;
}

Vec3 NoiseWind::Velocity(const Vec3& x, double t) const {
  Vec3 u = def_.mean;
  for (const Mode& m : modes_) u += m.curlAmp * std::cos(m.k.dot(x) + m.omega * t + m.phase);
  return u;
}

void NoiseWind::AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f,
                                size_t begin, size_t end) const {
  for (size_t i = begin; i < end; ++i) f[i - begin] += def_.drag * (Velocity(x[i], s.time) - v[i]);
}

void NoiseWind::AddJacobianProduct(const ParticleState& s, const Vec3*, const Vec3*, double,
                                   double cv, const Vec3* p, Vec3* y) const {
  if (cv == 0) return;
  for (size_t i = 0; i < s.size(); ++i) y[i] -= cv * def_.drag * p[i];  // df/dv = -drag I
}

Expected<std::shared_ptr<FieldGrid>> FieldGrid::Create(const Vec3& lo, const Vec3& hi,
                                                       std::array<int, 3> n,
                                                       std::vector<Vec3> samples, bool clamp) {
  using namespace check;
  for (int k = 0; k < 3; ++k) {
    if (Status st = Range("FieldGrid n[" + std::to_string(k) + "]", n[k], 2, 4096); !st.ok())
      return st.error();
  }
  const size_t want = size_t(n[0]) * size_t(n[1]) * size_t(n[2]);
  if (samples.size() != want) {
    return Error("FieldGrid has " + std::to_string(samples.size()) +
                 " samples, not n0 n1 n2 = " + std::to_string(want));
  }
  for (const auto& [name, v] : {std::pair{"FieldGrid lo", &lo}, std::pair{"FieldGrid hi", &hi}}) {
    if (Status st = Finite(name, *v, 1e12, "m"); !st.ok()) return st.error();
  }
  if (!(lo.array() < hi.array()).all())
    return Error("FieldGrid lo " + Vec(lo) + " is not below hi " + Vec(hi));
  for (size_t k = 0; k < samples.size(); ++k) {
    if (Status st =
            Finite("FieldGrid samples[" + std::to_string(k) + "]", samples[k], 1e12, "m/s^2");
        !st.ok()) {
      return st.error();
    }
  }
  return std::shared_ptr<FieldGrid>(new FieldGrid(lo, hi, n, std::move(samples), clamp));
}

FieldGrid::FieldGrid(const Vec3& lo, const Vec3& hi, std::array<int, 3> n,
                     std::vector<Vec3> samples, bool clamp)
    : lo_(lo), hi_(hi), n_(n), samples_(std::move(samples)), clamp_(clamp) {
  for (int k = 0; k < 3; ++k) inv_[k] = (n[k] - 1) / (hi[k] - lo[k]);
}

Vec3 FieldGrid::At(const Vec3& x) const {
  double t[3];
  int c[3];
  for (int k = 0; k < 3; ++k) {
    double g = (x[k] - lo_[k]) * inv_[k];
    if (!(g >= 0 && g <= n_[k] - 1)) {
      if (!clamp_) return Vec3::Zero();  // outside (or NaN)
      g = std::clamp(std::isnan(g) ? 0.0 : g, 0.0, double(n_[k] - 1));
    }
    c[k] = std::min(int(g), n_[k] - 2);
    t[k] = g - c[k];
  }
  auto S = [&](int dx, int dy, int dz) {
    return samples_[(size_t(c[2] + dz) * n_[1] + (c[1] + dy)) * n_[0] + (c[0] + dx)];
  };
  const Vec3 x00 = S(0, 0, 0) * (1 - t[0]) + S(1, 0, 0) * t[0];
  const Vec3 x10 = S(0, 1, 0) * (1 - t[0]) + S(1, 1, 0) * t[0];
  const Vec3 x01 = S(0, 0, 1) * (1 - t[0]) + S(1, 0, 1) * t[0];
  const Vec3 x11 = S(0, 1, 1) * (1 - t[0]) + S(1, 1, 1) * t[0];
  const Vec3 y0 = x00 * (1 - t[1]) + x10 * t[1];
  const Vec3 y1 = x01 * (1 - t[1]) + x11 * t[1];
  return y0 * (1 - t[2]) + y1 * t[2];
}

void FieldGrid::AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3*, Vec3* f,
                                size_t begin, size_t end) const {
  for (size_t i = begin; i < end; ++i) f[i - begin] += s.mass[i] * At(x[i]);
}

void Penalty::Anchor(uint32_t i, const Vec3& point, double ks, double kd) {
  maxIndex_ = std::max(maxIndex_, i);
  terms_.push_back({Kind::kAnchor, i, i, point, Vec3::Zero(), 0, ks, kd});
}
void Penalty::Distance(uint32_t i, uint32_t j, double distance, double ks, double kd) {
  maxIndex_ = std::max({maxIndex_, i, j});
  terms_.push_back({Kind::kDistance, i, j, Vec3::Zero(), Vec3::Zero(), distance, ks, kd});
}
void Penalty::OnPlane(uint32_t i, const Vec3& point, const Vec3& normal, double ks, double kd) {
  maxIndex_ = std::max(maxIndex_, i);
  terms_.push_back({Kind::kPlane, i, i, point, normal.normalized(), 0, ks, kd});
}
void Penalty::OnSphere(uint32_t i, const Vec3& centre, double radius, double ks, double kd) {
  maxIndex_ = std::max(maxIndex_, i);
  terms_.push_back({Kind::kSphere, i, i, centre, Vec3::Zero(), radius, ks, kd});
}

void Penalty::Renumber(const std::vector<uint32_t>& newIndex) {
  size_t kept = 0;
  maxIndex_ = 0;
  for (Term t : terms_) {
    t.i = t.i < newIndex.size() ? newIndex[t.i] : t.i;
    t.j = t.j < newIndex.size() ? newIndex[t.j] : t.j;
    if (t.i == kRemoved || t.j == kRemoved) continue;
    maxIndex_ = std::max({maxIndex_, t.i, t.j});
    terms_[kept++] = t;
  }
  terms_.resize(kept);
}

Status RandomDrift::Check(const ParticleState&) const {
  return check::Range("RandomDrift sigma", sigma_, 0, 1e12, "N");
}

Status Penalty::Check(const ParticleState& s) const {
  if (terms_.empty() || maxIndex_ < s.size()) return {};
  return check::Error("Penalty: a term names particle " + std::to_string(maxIndex_) +
                      ", but the system has " + std::to_string(s.size()) + " particles");
}

void Penalty::Accumulate(const ParticleState&, const Vec3* x, const Vec3* v, Vec3* f) const {
  for (const Term& t : terms_) {
    switch (t.kind) {
      case Kind::kAnchor: {  // a zero-length spring: f = -ks (x - p) - kd v
        f[t.i] -= t.ks * (x[t.i] - t.point) + t.kd * v[t.i];
        break;
      }
      case Kind::kDistance: {
        const Vec3 d = x[t.i] - x[t.j];
        const double len = d.norm();
        if (!(len > 0)) break;
        const Vec3 g = d / len;
        const Vec3 fi = -(t.ks * (len - t.value) + t.kd * (v[t.i] - v[t.j]).dot(g)) * g;
        f[t.i] += fi;
        f[t.j] -= fi;
        break;
      }
      case Kind::kPlane: {
        const double c = t.normal.dot(x[t.i] - t.point);
        f[t.i] -= (t.ks * c + t.kd * t.normal.dot(v[t.i])) * t.normal;
        break;
      }
      case Kind::kSphere: {
        const Vec3 d = x[t.i] - t.point;
        const double len = d.norm();
        if (!(len > 0)) break;
        const Vec3 g = d / len;
        f[t.i] -= (t.ks * (len - t.value) + t.kd * g.dot(v[t.i])) * g;
        break;
      }
    }
  }
}

void Penalty::AddJacobianProduct(const ParticleState&, const Vec3* x, const Vec3*, double cx,
                                 double cv, const Vec3* p, Vec3* y) const {
  for (const Term& t : terms_) {
    if (t.kind == Kind::kAnchor) {
      y[t.i] -= (cx * t.ks + cv * t.kd) * p[t.i];
    } else if (t.kind == Kind::kDistance) {
      const Vec3 d = x[t.i] - x[t.j];
      const double len = d.norm();
      if (!(len > 0)) continue;
      const Vec3 u = d / len;
      const Vec3 dp = p[t.i] - p[t.j];
      const double along = u.dot(dp);
      const double transverse = std::max(0.0, 1 - t.value / len);
      const Vec3 g =
          -cx * t.ks * (along * u + transverse * (dp - along * u)) - cv * t.kd * along * u;
      y[t.i] += g;
      y[t.j] -= g;
    }
  }
}

double Penalty::Energy(const Vec3* x) const {
  double e = 0;
  for (const Term& t : terms_) {
    double c = 0;
    switch (t.kind) {
      case Kind::kAnchor:
        c = (x[t.i] - t.point).norm();
        break;
      case Kind::kDistance:
        c = (x[t.i] - x[t.j]).norm() - t.value;
        break;
      case Kind::kPlane:
        c = t.normal.dot(x[t.i] - t.point);
        break;
      case Kind::kSphere:
        c = (x[t.i] - t.point).norm() - t.value;
        break;
    }
    e += 0.5 * t.ks * c * c;
  }
  return e;
}

}  // namespace sylva::particles
