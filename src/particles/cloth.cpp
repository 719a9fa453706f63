#include "particles/cloth.h"

#include <algorithm>
#include <cmath>

namespace sylva::particles {

Cloth::Cloth(const ClothDef& def) : def_(def) {
  def_.columns = std::max(def_.columns, 2);
  def_.rows = std::max(def_.rows, 2);
  const int nc = def_.columns, nr = def_.rows;
  const size_t n = size_t(nc) * size_t(nr);
  x_.resize(n);
  v_.assign(n, Vec3::Zero());
  w_.assign(n, double(n) / def_.mass);
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c < nc; ++c)
      x_[size_t(Index(c, r))] = def_.origin + def_.u * (double(c) / (nc - 1)) + def_.v * (double(r) / (nr - 1));
  for (int p : def_.pinned) {
    if (p >= 0 && size_t(p) < n) w_[size_t(p)] = 0;
  }
  auto link = [&](int c0, int r0, int c1, int r1, double compliance) {
    if (c1 < 0 || c1 >= nc || r1 < 0 || r1 >= nr) return;
    const uint32_t a = uint32_t(Index(c0, r0)), b = uint32_t(Index(c1, r1));
    constraints_.push_back({a, b, (x_[a] - x_[b]).norm(), compliance});
  };
  for (int r = 0; r < nr; ++r) {
    for (int c = 0; c < nc; ++c) {
      link(c, r, c + 1, r, def_.stretchCompliance);  // structural
      link(c, r, c, r + 1, def_.stretchCompliance);
      link(c, r, c + 1, r + 1, def_.shearCompliance);  // shear
      link(c + 1, r, c, r + 1, def_.shearCompliance);
      link(c, r, c + 2, r, def_.bendCompliance);  // bend
      link(c, r, c, r + 2, def_.bendCompliance);
      if (c + 1 < nc && r + 1 < nr) {
        const uint32_t a = uint32_t(Index(c, r)), b = uint32_t(Index(c + 1, r)),
                       d = uint32_t(Index(c, r + 1)), e = uint32_t(Index(c + 1, r + 1));
        tris_.push_back({a, d, b});
        tris_.push_back({b, d, e});
      }
    }
  }
  lambda_.assign(constraints_.size(), 0);
  if (def_.solver == ClothSolver::kImplicit) {
    implicit_ = std::make_unique<System>(1);
    implicit_->cgMaxIterations = std::max(1, def_.cgIterations);
    implicit_->cgTolerance = 1e-12;
    for (size_t i = 0; i < n; ++i) implicit_->state.Add(x_[i], Vec3::Zero(), w_[i] > 0 ? 1 / w_[i] : 0);
    auto springs = std::make_shared<Springs>();
    for (const Constraint& c : constraints_) {
      springs->Add(c.a, c.b, c.rest,
                   c.compliance > 0 ? std::min(1 / c.compliance, def_.implicitStiffness) : def_.implicitStiffness,
                   def_.implicitDamping);
    }
    implicit_->AddForce(springs);
    // Gravity, wind and damping read the current frame's values.
    implicit_->AddForce(std::make_shared<ForceFunction>(
        [this](const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) {
          for (size_t i = 0; i < s.size(); ++i) f[i] += s.mass[i] * (gravity_ - def_.damping * v[i]);
          AddWind(x, v, wind_, f);
        }));
  }
}

void Cloth::AddWind(const Vec3* x, const Vec3* v, const Vec3& wind, Vec3* f) const {
  if (def_.windDrag == 0) return;
  for (const auto& t : tris_) {
    const Vec3 e1 = x[t[1]] - x[t[0]], e2 = x[t[2]] - x[t[0]];
    const Vec3 cr = e1.cross(e2);
    const double area2 = cr.norm();
    if (!(area2 > 0)) continue;
    const Vec3 nrm = cr / area2;
    const Vec3 rel = wind - (v[t[0]] + v[t[1]] + v[t[2]]) / 3;
    const Vec3 fw = def_.windDrag * 0.5 * area2 * rel.dot(nrm) * nrm / 3;
    for (uint32_t k : t) f[k] += fw;
  }
}

double Cloth::MaxStretch() const {
  double worst = 0;
  for (const Constraint& c : constraints_) {
    if (c.compliance != def_.stretchCompliance) continue;
    worst = std::max(worst, ((x_[c.a] - x_[c.b]).norm() - c.rest) / c.rest);
  }
  return worst;
}

void Cloth::StepImplicit(double dt, const Vec3& gravity, const Vec3& wind) {
  gravity_ = gravity;
  wind_ = wind;
  implicit_->state.position = x_;  // the caller may have moved particles
  implicit_->state.velocity = v_;
  const int subs = std::max(def_.implicitSubsteps, 1);
  for (int s = 0; s < subs; ++s) {
    // Cloth is well-behaved input; a fault here is a bug in the set-up.
    if (!implicit_->Step(dt / subs, Integrator::kImplicitEuler).ok()) break;
  }
  x_ = implicit_->state.position;
  v_ = implicit_->state.velocity;
}

void Cloth::Step(double dt, const Vec3& gravity, const Vec3& wind) {
  if (implicit_) return StepImplicit(dt, gravity, wind);
  const int subs = std::max(def_.substeps, 1);
  const double h = dt / subs;
  const size_t n = x_.size();
  std::vector<Vec3>& fext = fext_;
  fext.resize(n);
  for (int s = 0; s < subs; ++s) {
    // External forces: gravity, and wind on each triangle by its area and
    // the normal component of the air speed relative to it.
    std::fill(fext.begin(), fext.end(), Vec3::Zero());
    AddWind(x_.data(), v_.data(), wind, fext.data());
    prev_ = x_;
    const double keep = std::max(0.0, 1 - def_.damping * h);
    for (size_t i = 0; i < n; ++i) {
      if (w_[i] == 0) continue;
      v_[i] = (v_[i] + h * (gravity + fext[i] * w_[i])) * keep;
      x_[i] += h * v_[i];
    }
    std::fill(lambda_.begin(), lambda_.end(), 0.0);
    for (int it = 0; it < def_.iterations; ++it) {
      for (size_t k = 0; k < constraints_.size(); ++k) {
        const Constraint& c = constraints_[k];
        const double wsum = w_[c.a] + w_[c.b];
        if (wsum == 0) continue;
        const Vec3 d = x_[c.a] - x_[c.b];
        const double len = d.norm();
        if (!(len > 1e-12)) continue;
        const Vec3 dir = d / len;
        const double alpha = c.compliance / (h * h);
        const double dl = (-(len - c.rest) - alpha * lambda_[k]) / (wsum + alpha);
        lambda_[k] += dl;
        x_[c.a] += w_[c.a] * dl * dir;
        x_[c.b] -= w_[c.b] * dl * dir;
      }
    }
    for (size_t i = 0; i < n; ++i) v_[i] = (x_[i] - prev_[i]) / h;
  }
}

}  // namespace sylva::particles
