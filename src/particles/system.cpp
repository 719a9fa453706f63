#include "particles/system.h"

#include <cmath>

namespace sylva::particles {

uint32_t ParticleState::Add(const Vec3& p, const Vec3& v, double m, double life) {
  position.push_back(p);
  velocity.push_back(v);
  mass.push_back(m);
  invMass.push_back(m > 0 ? 1 / m : 0);
  age.push_back(0);
  lifetime.push_back(life);
  color.push_back(Vec3f(1, 1, 1));
  id.push_back(nextId);
  return nextId++;
}

void Gravity::Accumulate(const ParticleState& s, const Vec3*, const Vec3*, Vec3* f) const {
  for (size_t i = 0; i < s.size(); ++i) {
    if (s.invMass[i] > 0) f[i] += s.mass[i] * g_;
  }
}

void Drag::Accumulate(const ParticleState& s, const Vec3*, const Vec3* v, Vec3* f) const {
  for (size_t i = 0; i < s.size(); ++i) f[i] -= (k1_ + k2_ * v[i].norm()) * v[i];
}

void Springs::Accumulate(const ParticleState&, const Vec3* x, const Vec3* v, Vec3* f) const {
  for (const Spring& sp : springs_) {
    const Vec3 d = x[sp.a] - x[sp.b];
    const double len = d.norm();
    if (!(len > 1e-300)) continue;
    const Vec3 dir = d / len;
    const double rate = (v[sp.a] - v[sp.b]).dot(dir);
    const Vec3 fa = -(sp.ks * (len - sp.rest) + sp.kd * rate) * dir;
    f[sp.a] += fa;
    f[sp.b] -= fa;
  }
}

void System::Accelerations(const Vec3* x, const Vec3* v, Vec3* a) const {
  const size_t n = state.size();
  f_.assign(n, Vec3::Zero());
  for (const auto& force : forces_) force->Accumulate(state, x, v, f_.data());
  for (size_t i = 0; i < n; ++i) a[i] = f_[i] * state.invMass[i];
}

double System::KineticEnergy() const {
  double e = 0;
  for (size_t i = 0; i < state.size(); ++i) {
    if (state.invMass[i] > 0) e += 0.5 * state.mass[i] * state.velocity[i].squaredNorm();
  }
  return e;
}

void System::Step(double h, Integrator integrator) {
  const size_t n = state.size();
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  before_ = X;
  vbefore_ = V;
  for (auto& k : k_) k.resize(n);
  x_.resize(n);
  v_.resize(n);
  Vec3* a = k_[0].data();
  switch (integrator) {
    case Integrator::kExplicitEuler:
      Accelerations(X.data(), V.data(), a);
      for (size_t i = 0; i < n; ++i) {
        X[i] += h * V[i];
        V[i] += h * a[i];
      }
      break;
    case Integrator::kSymplecticEuler:
      Accelerations(X.data(), V.data(), a);
      for (size_t i = 0; i < n; ++i) {
        V[i] += h * a[i];
        X[i] += h * V[i];
      }
      break;
    case Integrator::kMidpoint: {
      Accelerations(X.data(), V.data(), a);
      for (size_t i = 0; i < n; ++i) {
        x_[i] = X[i] + 0.5 * h * V[i];
        v_[i] = V[i] + 0.5 * h * a[i];
      }
      Vec3* a2 = k_[1].data();
      Accelerations(x_.data(), v_.data(), a2);
      for (size_t i = 0; i < n; ++i) {
        X[i] += h * v_[i];
        V[i] += h * a2[i];
      }
      break;
    }
    case Integrator::kRK4: {
      // k_x = v, k_v = a(x, v) at four stages.
      Vec3 *a1 = k_[0].data(), *a2 = k_[1].data(), *a3 = k_[2].data(), *a4 = k_[3].data();
      Vec3 *v2 = k_[4].data(), *v3 = k_[5].data(), *v4 = k_[6].data();
      Accelerations(X.data(), V.data(), a1);
      for (size_t i = 0; i < n; ++i) {
        x_[i] = X[i] + 0.5 * h * V[i];
        v2[i] = V[i] + 0.5 * h * a1[i];
      }
      Accelerations(x_.data(), v2, a2);
      for (size_t i = 0; i < n; ++i) {
        x_[i] = X[i] + 0.5 * h * v2[i];
        v3[i] = V[i] + 0.5 * h * a2[i];
      }
      Accelerations(x_.data(), v3, a3);
      for (size_t i = 0; i < n; ++i) {
        x_[i] = X[i] + h * v3[i];
        v4[i] = V[i] + h * a3[i];
      }
      Accelerations(x_.data(), v4, a4);
      for (size_t i = 0; i < n; ++i) {
        X[i] += h / 6 * (V[i] + 2 * v2[i] + 2 * v3[i] + v4[i]);
        V[i] += h / 6 * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i]);
      }
      break;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (state.invMass[i] == 0) {  // immovable
      X[i] = before_[i];
      V[i] = Vec3::Zero();
    }
  }
  Collide(before_, vbefore_, h);
  for (size_t i = 0; i < n; ++i) state.age[i] += h;
  time += h;
}

void System::Collide(const std::vector<Vec3>& x0, const std::vector<Vec3>& v0, double h) {
  std::vector<Vec3>& X = state.position;
  std::vector<Vec3>& V = state.velocity;
  for (const Plane& pl : planes_) {
    for (size_t i = 0; i < X.size(); ++i) {
      const double d1 = pl.normal.dot(X[i] - pl.point);
      if (d1 >= 0) continue;
      const double d0 = pl.normal.dot(x0[i] - pl.point);
      // Time of contact by linear interpolation: the fraction s of the step
      // at which the path meets the plane (0 for a particle already below).
      const double s = d0 > 0 ? d0 / (d0 - d1) : 0.0;
      const Vec3 dv = V[i] - v0[i];               // the step's velocity change
      const Vec3 xc = x0[i] + s * (X[i] - x0[i]);  // on the plane
      Vec3 vc = v0[i] + s * dv;                     // velocity at contact
      const double vn = vc.dot(pl.normal);
      if (vn < 0) vc = (vc - vn * pl.normal) * (1 - pl.friction) - pl.restitution * vn * pl.normal;
      // The rest of the step from the contact, with the same acceleration.
      const double rest = (1 - s) * h;
      const Vec3 restDv = (1 - s) * dv;
      X[i] = xc + rest * (vc + 0.5 * restDv);
      V[i] = vc + restDv;
      // Never leave a particle below the plane (resting contact at the end).
      const double below = pl.normal.dot(X[i] - pl.point);
      if (below < 0) {
        X[i] -= below * pl.normal;
        const double vn2 = V[i].dot(pl.normal);
        if (vn2 < 0) V[i] -= vn2 * pl.normal;
      }
    }
  }
}

}  // namespace sylva::particles
