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
}

void Cloth::Step(double dt, const Vec3& gravity, const Vec3& wind) {
  const int subs = std::max(def_.substeps, 1);
  const double h = dt / subs;
  const size_t n = x_.size();
  std::vector<Vec3> fext(n);
  for (int s = 0; s < subs; ++s) {
    // External forces: gravity, and wind on each triangle by its area and
    // the normal component of the air speed relative to it.
    std::fill(fext.begin(), fext.end(), Vec3::Zero());
    if (def_.windDrag != 0) {
      for (const auto& t : tris_) {
        const Vec3 e1 = x_[t[1]] - x_[t[0]], e2 = x_[t[2]] - x_[t[0]];
        const Vec3 cr = e1.cross(e2);
        const double area2 = cr.norm();
        if (!(area2 > 0)) continue;
        const Vec3 nrm = cr / area2;
        const Vec3 rel = wind - (v_[t[0]] + v_[t[1]] + v_[t[2]]) / 3;
        const Vec3 f = def_.windDrag * 0.5 * area2 * rel.dot(nrm) * nrm / 3;
        for (uint32_t k : t) fext[k] += f;
      }
    }
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
