#include "particles/cloth.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

#include "particles/cloth_collision.h"
#include "particles/def_check.h"

namespace sylva::particles {

// Gravity, damping and wind at the current frame's values, on the implicit
// solver's threads.
class Cloth::ExternalForce : public Force {
 public:
  explicit ExternalForce(Cloth* cloth) : cloth_(cloth) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override {
    const size_t n = s.size();
    const Vec3 g = cloth_->gravity_;
    const double damping = cloth_->def_.damping;
    ForRanges(pool_, n, BalancedGrain(pool_, n, 512, 4096), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) f[i] += s.mass[i] * (g - damping * v[i]);
    });
    cloth_->AddWind(pool_, x, v, cloth_->wind_, f);
  }

 private:
  Cloth* cloth_;
};

Status Validate(const ClothDef& d) {
  using namespace check;
  SYLVA_CHECK_OK(Range("ClothDef.columns", d.columns, 2, 10000));
  SYLVA_CHECK_OK(Range("ClothDef.rows", d.rows, 2, 10000));
  const double n = double(d.columns) * double(d.rows);
  SYLVA_CHECK_OK(Range("ClothDef.columns * rows", n, 4, 1e7, "particles"));
  SYLVA_CHECK_OK(Finite("ClothDef.origin", d.origin, 1e12, "m"));
  SYLVA_CHECK_OK(Finite("ClothDef.u", d.u, 1e12, "m"));
  SYLVA_CHECK_OK(Finite("ClothDef.v", d.v, 1e12, "m"));
  if (!(d.u.cross(d.v).squaredNorm() > 0)) {
    return Error("ClothDef.u " + Vec(d.u) + " and v " + Vec(d.v) +
                 " are parallel or zero: the cloth has no area");
  }
  SYLVA_CHECK_OK(Range("ClothDef.mass", d.mass, 1e-12, 1e12, "kg"));
  SYLVA_CHECK_OK(Range("ClothDef.stretchCompliance", d.stretchCompliance, 0, 1e12, "m/N"));
  SYLVA_CHECK_OK(Range("ClothDef.shearCompliance", d.shearCompliance, 0, 1e12, "m/N"));
  SYLVA_CHECK_OK(Range("ClothDef.bendCompliance", d.bendCompliance, 0, 1e12, "m/N"));
  SYLVA_CHECK_OK(Range("ClothDef.substeps", d.substeps, 1, 10000));
  SYLVA_CHECK_OK(Range("ClothDef.iterations", d.iterations, 1, 10000));
  SYLVA_CHECK_OK(Range("ClothDef.damping", d.damping, 0, 1e6, "1/s"));
  SYLVA_CHECK_OK(Range("ClothDef.windDrag", d.windDrag, 0, 1e6));
  SYLVA_CHECK_OK(Range("ClothDef.windLift", d.windLift, -1e6, 1e6));
  SYLVA_CHECK_OK(Range("ClothDef.windFriction", d.windFriction, 0, 1e6));
  for (size_t k = 0; k < d.pinned.size(); ++k) {
    SYLVA_CHECK_OK(Range("ClothDef.pinned[" + std::to_string(k) + "]", d.pinned[k], 0, n - 1));
  }
  SYLVA_CHECK_OK(Range("ClothDef.thickness", d.thickness, 0, 1e12, "m"));
  SYLVA_CHECK_OK(Range("ClothDef.selfFriction", d.selfFriction, 0, 1e3));
  SYLVA_CHECK_OK(Range("ClothDef.threads", d.threads, 0, 256));
  SYLVA_CHECK_OK(Range("ClothDef.implicitStiffness", d.implicitStiffness, 1e-12, 1e12, "N/m"));
  SYLVA_CHECK_OK(Range("ClothDef.implicitDamping", d.implicitDamping, 0, 1e12, "N s/m"));
  SYLVA_CHECK_OK(Range("ClothDef.implicitSubsteps", d.implicitSubsteps, 1, 10000));
  SYLVA_CHECK_OK(Range("ClothDef.cgIterations", d.cgIterations, 1, 100000));
  SYLVA_CHECK_OK(Range("ClothDef.implicitStrainLimit", d.implicitStrainLimit, 0, 1e6));
  SYLVA_CHECK_OK(Range("ClothDef.implicitStrainIterations", d.implicitStrainIterations, 1, 100000));
  return {};
}

Expected<std::unique_ptr<Cloth>> Cloth::Create(const ClothDef& def) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  return std::unique_ptr<Cloth>(new Cloth(def));
}

Cloth::Cloth(const ClothDef& def) : def_(def) {
  const int nc = def_.columns, nr = def_.rows;
  const size_t n = size_t(nc) * size_t(nr);
  x_.resize(n);
  v_.assign(n, Vec3::Zero());
  w_.assign(n, double(n) / def_.mass);
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c < nc; ++c)
      x_[size_t(Index(c, r))] =
          def_.origin + def_.u * (double(c) / (nc - 1)) + def_.v * (double(r) / (nr - 1));
  for (int p : def_.pinned) w_[size_t(p)] = 0;  // in range (Validate)
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
  // Greedy colouring in creation order, then a stable sort by colour.
  {
    std::vector<uint64_t> used(n, 0);
    std::vector<int> color(constraints_.size());
    int colors = 0;
    for (size_t k = 0; k < constraints_.size(); ++k) {
      const uint64_t taken = used[constraints_[k].a] | used[constraints_[k].b];
      int c = 0;
      while (c < 63 && (taken >> c & 1)) ++c;
      color[k] = c;
      used[constraints_[k].a] |= 1ULL << c;
      used[constraints_[k].b] |= 1ULL << c;
      colors = std::max(colors, c + 1);
    }
    lastColourShared_ = colors == 64;
    std::vector<Constraint> sorted;
    sorted.reserve(constraints_.size());
    colorStart_.clear();
    for (int c = 0; c < colors; ++c) {
      colorStart_.push_back(sorted.size());
      for (size_t k = 0; k < constraints_.size(); ++k) {
        if (color[k] == c) sorted.push_back(constraints_[k]);
      }
    }
    colorStart_.push_back(sorted.size());
    constraints_ = std::move(sorted);
  }
  lambda_.assign(constraints_.size(), 0);
  // Tethers to the nearest pins in rest space.
  std::vector<uint32_t> pins;
  for (size_t i = 0; i < n; ++i) {
    if (w_[i] == 0) pins.push_back(uint32_t(i));
  }
  if (def_.longRangeAttachments && !pins.empty() && def_.solver == ClothSolver::kXPBD) {
    tethers_.assign(n * xpbd::kTethers, xpbd::Tether{UINT32_MAX, 0});
    for (size_t i = 0; i < n; ++i) {
      if (w_[i] == 0) continue;
      xpbd::Tether* t = &tethers_[i * xpbd::kTethers];
      for (uint32_t p : pins) {
        xpbd::Tether cand{p, (x_[i] - x_[p]).norm()};
        for (int k = 0; k < xpbd::kTethers; ++k) {
          if (t[k].pin == UINT32_MAX || cand.rest < t[k].rest) std::swap(cand, t[k]);
        }
      }
    }
  }
  if (def_.thickness > 0)
    self_ = std::make_unique<clothcontact::SelfCollision>(x_, def_.thickness, def_.selfFriction);
  if (def_.pool && def_.solver == ClothSolver::kXPBD) {
    pool_ = def_.pool->threads() > 1 ? def_.pool : nullptr;
  } else if (def_.threads != 1 && def_.solver == ClothSolver::kXPBD) {  // implicit: its own
    const int threads = def_.threads <= 0 ? ThreadPool::HardwareThreads() : def_.threads;
    if (threads > 1) ownPool_ = std::make_unique<ThreadPool>(threads);
    pool_ = ownPool_.get();
  }
  if (def_.solver == ClothSolver::kImplicit) {
    implicit_ = std::make_unique<System>(def_.pool ? 1 : def_.threads);
    if (def_.pool) implicit_->UsePool(def_.pool);
    implicit_->cgMaxIterations = def_.cgIterations;
    implicit_->cgTolerance = 1e-12;
    for (size_t i = 0; i < n; ++i) {
      if (w_[i] > 0) {
        implicit_->state.Add(x_[i], Vec3::Zero(), 1 / w_[i]);
      } else {
        implicit_->state.AddPinned(x_[i], def_.mass / double(n));
      }
    }
    auto springs = std::make_shared<Springs>();
    for (const Constraint& c : constraints_) {
      const Status added =
          springs->Add(c.a, c.b, c.rest,
                       c.compliance > 0 ? std::min(1 / c.compliance, def_.implicitStiffness)
                                        : def_.implicitStiffness,
                       def_.implicitDamping);
      SYLVA_ASSERT(added.ok());  // in range by Validate(ClothDef)
    }
    implicit_->AddForce(springs);
    implicit_->AddForce(std::make_shared<ExternalForce>(this));
  }
}

Cloth::~Cloth() = default;

Status Cloth::AddCollider(Collider c, double thickness) {
  SYLVA_CHECK_OK(Validate(c));
  SYLVA_CHECK_OK(check::Range("Cloth.AddCollider thickness", thickness, 0, 1e3, "m"));
  if (c.response == Response::kKill)
    return check::Error(
        "Cloth.AddCollider: a kKill collider cannot take cloth (a cloth particle "
        "cannot die); use kBounce or kStick");
  if (implicit_) SYLVA_CHECK_OK(implicit_->AddCollider(c));
  colliders_.push_back(std::move(c));
  colliderThickness_.push_back(thickness);
  return {};
}

Status Cloth::SetCollider(size_t index, Collider c) {
  if (index >= colliders_.size())
    return check::Error("Cloth.SetCollider: collider " + std::to_string(index) + " of " +
                        std::to_string(colliders_.size()));
  SYLVA_CHECK_OK(Validate(c));
  if (c.response == Response::kKill)
    return check::Error("Cloth.SetCollider: a kKill collider cannot take cloth");
  if (implicit_) SYLVA_CHECK_OK(implicit_->SetCollider(index, c));
  colliders_[index] = std::move(c);
  return {};
}

void Cloth::AddWind(ThreadPool* pool, const Vec3* x, const Vec3* v, const Vec3& wind, Vec3* f) {
  if (externalForce_) {
    const size_t n = x_.size();
    ForRanges(pool, n, BalancedGrain(pool, n, 512, 4096), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (w_[i] > 0) f[i] += externalForce_(i, x[i], v[i]);
    });
  }
  const double cd = def_.windDrag, cl = def_.windLift, cf = def_.windFriction;
  if (cd == 0 && cl == 0 && cf == 0) return;
  const WindField* field = windField_;
  // Each triangle's force, then each particle gathers from the (up to six)
  // triangles around it in a fixed order: parallel, and the same sums for
  // any thread count.
  const size_t nt = tris_.size();
  triForce_.resize(nt);
  ForRanges(pool, nt, BalancedGrain(pool, nt, 512, 4096), [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const auto& t = tris_[k];
      const Vec3 cr = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
      const double area2 = cr.norm();
      const Vec3 air = field ? (*field)((x[t[0]] + x[t[1]] + x[t[2]]) / 3) : wind;
      const Vec3 u = air - (v[t[0]] + v[t[1]] + v[t[2]]) / 3;
      const double uu = u.squaredNorm();
      if (!std::isfinite(uu)) {  // a non-finite wind: the corners report it as theirs
        triForce_[k] = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      if (!(area2 > 0) || !(uu > 0)) {
        triForce_[k] = Vec3::Zero();
        continue;
      }
      const Vec3 n = cr / area2;
      const double un = u.dot(n);
      // A (n.u) [c_l n + (c_d - c_l) (n.u) u / |u|^2]: drag along u is
      // c_d A |u| cos^2, and what is left of c_l A (n.u) n is the lift.
      Vec3 fw = un * (cl * n + ((cd - cl) * un / uu) * u);
      if (cf != 0) fw += cf * (u - un * n);
      triForce_[k] = (0.5 * area2 / 3) * fw;  // a third to each corner
    }
  });
  // Cell (c, r) holds triangles 2 cell = (a, d, b) and 2 cell + 1 = (b, d, e)
  // with a = (c, r), b = (c+1, r), d = (c, r+1), e = (c+1, r+1).
  const int nc = def_.columns, nr = def_.rows;
  const size_t n = x_.size();
  ForRanges(pool, n, BalancedGrain(pool, n, 512, 4096), [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const int c = int(i % size_t(nc)), r = int(i / size_t(nc));
      auto cell = [&](int cc, int rr) { return 2 * (size_t(rr) * size_t(nc - 1) + size_t(cc)); };
      Vec3 sum = Vec3::Zero();
      if (c + 1 < nc && r + 1 < nr) sum += triForce_[cell(c, r)];  // as a
      if (c > 0 && r + 1 < nr) {                                   // as b
        const size_t k = cell(c - 1, r);
        sum += triForce_[k] + triForce_[k + 1];
      }
      if (c + 1 < nc && r > 0) {  // as d
        const size_t k = cell(c, r - 1);
        sum += triForce_[k] + triForce_[k + 1];
      }
      if (c > 0 && r > 0) sum += triForce_[cell(c - 1, r - 1) + 1];  // as e
      f[i] += sum;
    }
  });
}

double Cloth::MaxStretch() const {
  double worst = 0;
  for (const Constraint& c : constraints_) {
    if (c.compliance != def_.stretchCompliance) continue;
    worst = std::max(worst, ((x_[c.a] - x_[c.b]).norm() - c.rest) / c.rest);
  }
  return worst;
}

Status Cloth::FindNonFinite(const char* when) {
  for (size_t i = 0; i < x_.size(); ++i) {
    if (x_[i].allFinite() && v_[i].allFinite()) continue;
    const int c = int(i % size_t(def_.columns)), r = int(i / size_t(def_.columns));
    Diagnostic d = check::Error(
        check::Cat("cloth: frame ", std::to_string(frames_), ": particle ", std::to_string(i),
                   " (column ", std::to_string(c), ", row ", std::to_string(r), ") has position ",
                   check::Vec(x_[i]), " and velocity ", check::Vec(v_[i]), " (not finite) ", when,
                   " the frame; the cloth refuses further frames"));
    d.kind = ErrorKind::kRuntime;
    fault_ = d;
    return d;
  }
  return {};
}

Status Cloth::StepImplicit(double dt, const Vec3& gravity, const Vec3& wind) {
  gravity_ = gravity;
  wind_ = wind;
  SYLVA_CHECK_OK(FindNonFinite("before"));  // the caller may have moved particles
  implicit_->state.position = x_;
  implicit_->state.velocity = v_;
  const int subs = def_.implicitSubsteps;
  for (int s = 0; s < subs; ++s) {
    if (self_) selfPrev_ = implicit_->state.position;
    if (Status st = implicit_->Step(dt / subs, Integrator::kImplicitEuler); !st.ok()) {
      Diagnostic d = st.error();
      d.message = "cloth: frame " + std::to_string(frames_) + ", implicit substep " +
                  std::to_string(s) + ": " + d.message;
      fault_ = d;
      return d;
    }
    // A kStick collider makes the particles it holds immovable in the
    // particle system: so in the cloth too (self-collision, strain limits).
    for (size_t i = 0; i < w_.size(); ++i) {
      if (w_[i] > 0 && implicit_->state.invMass[i] == 0) {
        w_[i] = 0;
        strainBuilt_ = false;  // rebuilt with the new pin
      }
    }
    // The strain limiter before the self-collision pass, which gets the
    // last word: the limiter knows nothing of layers.
    if (def_.implicitStrainLimit > 0)
      LimitStrain(implicit_->state.position, implicit_->state.velocity, dt / subs);
    if (self_) {  // after the step: the correction's velocity is dx / h
      ParticleState& ps = implicit_->state;
      const size_t moved =
          self_->Pass(def_.pool, selfPrev_.data(), ps.position.data(), w_.data(), selfDx_);
      lastContacts_ += moved;
      const double invH = subs / dt;
      for (size_t i = 0; i < ps.size(); ++i) {
        ps.position[i] += selfDx_[i];
        ps.velocity[i] += invH * selfDx_[i];
      }
    }
  }
  x_ = implicit_->state.position;
  v_ = implicit_->state.velocity;
  return FindNonFinite("after");
}

Status Cloth::Step(double dt, const Vec3& gravity, const Vec3& wind) {
  return StepAny(dt, gravity, wind, nullptr);
}

Status Cloth::StepInWindField(double dt, const Vec3& gravity, const WindField& wind) {
  if (!wind) return Step(dt, gravity, Vec3::Zero());
  return StepAny(dt, gravity, Vec3::Zero(), &wind);
}

Status Cloth::StepAny(double dt, const Vec3& gravity, const Vec3& wind, const WindField* field) {
  if (fault_) return *fault_;
  if (!(dt > 0 && dt <= 1e6))
    return check::Error("Cloth.Step dt " + check::Num(dt) + " is outside (0, 1e+06] s");
  SYLVA_CHECK_OK(check::Finite("Cloth.Step gravity", gravity, 1e12, "m/s^2"));
  SYLVA_CHECK_OK(check::Finite("Cloth.Step wind", wind, 1e12, "m/s"));
  windField_ = field;
  lastContacts_ = 0;
  Status st = implicit_ ? StepImplicit(dt, gravity, wind) : StepXpbd(dt, gravity, wind);
  windField_ = nullptr;
  ++frames_;
  return st;
}

Status Cloth::StepXpbd(double dt, const Vec3& gravity, const Vec3& wind) {
  const int subs = def_.substeps;
  const double h = dt / subs;
  const size_t n = x_.size();
  ThreadPool* pool = pool_;
  // Wind once a frame (it changes slowly next to the substeps).
  fext_.assign(n, Vec3::Zero());
  AddWind(pool, x_.data(), v_.data(), wind, fext_.data());
  // The masses change only when a particle sticks (which resets projH_).
  if (!(projH_ == h && proj_.size() == constraints_.size())) BuildProjections(h);
  const double invH = 1 / h;
  const bool keepLambda = def_.iterations > 1;
  // The substeps run on padded positions, velocities and forces (see
  // xpbd.h), loaded from x_ and v_ here (the caller may have moved
  // particles) and stored back at the end.
  x4_.resize(n);
  v4_.resize(n);
  prev4_.resize(n);
  fext4_.resize(n);
  xpbd::Point4* x = x4_.data();
  const xpbd::Particles parts{x,
                              v4_.data(),
                              prev4_.data(),
                              fext4_.data(),
                              w_.data(),
                              tethers_.empty() ? nullptr : tethers_.data(),
                              {gravity.x(), gravity.y(), gravity.z()},
                              h,
                              invH,
                              std::max(0.0, 1 - def_.damping * h)};
  auto pad = [](const Vec3& p) { return xpbd::Point4{{p.x(), p.y(), p.z(), 0}}; };
  const size_t grain = BalancedGrain(pool, n, 512, 4096);
  // Non-finite particles are flagged as the state is loaded and stored.
  std::atomic<bool> bad{false};
  ForRanges(pool, n, grain, [&](size_t b, size_t e) {
    bool ok = true;
    for (size_t i = b; i < e; ++i) {
      ok &= x_[i].allFinite() & v_[i].allFinite();
      x4_[i] = pad(x_[i]);
      v4_[i] = pad(v_[i]);
      fext4_[i] = pad(fext_[i]);
    }
    if (!ok) bad.store(true, std::memory_order_relaxed);
    xpbd::PredictRange(parts, b, e);
  });
  if (bad.load()) return FindNonFinite("before");
  for (int s = 0; s < subs; ++s) {
    for (int it = 0; it < def_.iterations; ++it) {
      // Colour by colour: no two constraints of a colour share a particle,
      // so a colour's projections are independent (and run in parallel)
      // and the result does not depend on the thread count.
      for (size_t c = 0; c + 1 < colorStart_.size(); ++c) {
        const size_t first = colorStart_[c], count = colorStart_[c + 1] - first;
        if (lastColourShared_ && c + 2 == colorStart_.size()) {
          xpbd::ProjectRange(xpbd::Kernel::kScalar, it == 0, keepLambda, proj_.data(),
                             lambda_.data(), x, first, first + count);
          continue;
        }
        ForRanges(pool, count, BalancedGrain(pool, count, 256, 4096), [&](size_t b, size_t e) {
          xpbd::ProjectRange(kernel_, it == 0, keepLambda, proj_.data(), lambda_.data(), x,
                             first + b, first + e);
        });
      }
    }
    if (self_ || !colliders_.empty()) {
      ContactsXpbd(pool);
      if (projH_ == 0) BuildProjections(h);  // a particle stuck: it is a pin now
    }
    // This substep's attachments and velocities, fused with the next one's
    // prediction (or the store back).
    const bool last = s + 1 == subs;
    ForRanges(pool, n, grain, [&](size_t b, size_t e) {
      xpbd::FinishRange(kernel_, parts, !last, b, e);
      if (!last) return;
      bool ok = true;
      for (size_t i = b; i < e; ++i) {
        x_[i] = Vec3(x4_[i].p[0], x4_[i].p[1], x4_[i].p[2]);
        v_[i] = Vec3(v4_[i].p[0], v4_[i].p[1], v4_[i].p[2]);
        ok &= x_[i].allFinite() & v_[i].allFinite();
      }
      if (!ok) bad.store(true, std::memory_order_relaxed);
    });
  }
  return bad.load() ? FindNonFinite("after") : Status{};
}

void Cloth::BuildProjections(double h) {
  const size_t m = constraints_.size();
  projH_ = h;
  proj_.resize(m);
  for (size_t k = 0; k < m; ++k) {
    const Constraint& c = constraints_[k];
    const double alphaT = c.compliance / (h * h);
    const double denom = w_[c.a] + w_[c.b] + alphaT;
    const double scale = denom > 0 ? 1 / denom : 0;  // 0: both ends pinned, nothing moves
    proj_[k] = {c.a, c.b, c.rest, scale, w_[c.a] * scale, w_[c.b] * scale, alphaT};
  }
}

void Cloth::ContactsXpbd(ThreadPool* pool) {
  const size_t n = x_.size();
  const size_t grain = BalancedGrain(pool, n, 512, 4096);
  auto get = [](const xpbd::Point4& p) { return Vec3(p.p[0], p.p[1], p.p[2]); };
  auto put = [](xpbd::Point4& p, const Vec3& v) {
    p.p[0] = v.x();
    p.p[1] = v.y();
    p.p[2] = v.z();
  };
  if (self_) {
    selfX_.resize(n);
    selfPrev_.resize(n);
    ForRanges(pool, n, grain, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        selfX_[i] = get(x4_[i]);
        selfPrev_[i] = get(prev4_[i]);
      }
    });
    lastContacts_ += self_->Pass(pool, selfPrev_.data(), selfX_.data(), w_.data(), selfDx_);
    ForRanges(pool, n, grain, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (selfDx_[i] != Vec3::Zero()) put(x4_[i], selfX_[i] + selfDx_[i]);
    });
  }
  if (colliders_.empty()) return;
  std::atomic<size_t> touched{0};
  std::atomic<bool> stuck{false};
  ForRanges(pool, n, grain, [&](size_t b, size_t e) {
    size_t count = 0;
    for (size_t i = b; i < e; ++i) {
      if (w_[i] == 0) continue;
      Vec3 x = get(x4_[i]);
      bool any = false;
      for (size_t k = 0; k < colliders_.size() && !any; ++k)
        any = colliders_[k].MayHit(get(prev4_[i]), x, colliderThickness_[k]);
      if (!any) continue;
      const Collider* hit =
          clothcontact::Collide(colliders_, colliderThickness_, get(prev4_[i]), x);
      if (!hit) continue;
      put(x4_[i], x);
      ++count;
      if (hit->response == Response::kStick) {  // immovable from now on, as a pin
        w_[i] = 0;
        v4_[i] = xpbd::Point4{{0, 0, 0, 0}};
        prev4_[i] = x4_[i];
        stuck.store(true, std::memory_order_relaxed);
      }
    }
    touched.fetch_add(count, std::memory_order_relaxed);
  });
  lastContacts_ += touched.load();
  if (stuck.load()) projH_ = 0;  // the projections' shares change: rebuilt below
}

// Strain limiting (Provot 1995) on a hierarchy of grids. Gauss-Seidel
// passes over the structural links carry a correction about two links a
// pass, so a sheet 100 particles across needed thousands of them (1,000
// passes held a 100 x 100 sheet hanging from two corners at 1/10 s to
// 18 %, not 10 %). As in hierarchical position-based dynamics (Muller,
// "Hierarchical position based dynamics", VRIPHYS 2008), coarser grids
// carry the correction across the sheet: the particles of every 2nd, 4th,
// 8th ... column and row (with the last column and row and those of the
// pins), linked to their neighbours on that grid with the rest distance
// between them. A fine link within the limit keeps a coarse one within it,
// so the coarse links are limited alike (one-sided: only a stretched link
// is shortened).
//
// A cycle: two passes over the cloth's own links, and if a link is still
// past the limit, each coarse grid from the coarsest, two passes over its
// links, the particles between its nodes moved by the bilinear
// interpolation of the nodes' moves. Cycles repeat until a pass over the
// cloth's links finds none past the limit, at most implicitStrainIterations
// of them; a stretch that is local never reaches the coarse grids. A
// stretched link goes back to 80 % of the limit (8 % for 10 %): the slack
// lets its neighbours' corrections land without pushing it over again, and
// the cycles converge several times faster than from 98 %.
//
// With self-collision the coarse grids are left out: a coarse cell of a
// folded sheet holds both layers, and the moves it gives them are larger
// than the self-collision pass can take back (a folded sheet dropped on a
// ball went through itself).
void Cloth::BuildStrainLimiter() {
  const double limit = 1 + def_.implicitStrainLimit;
  const double target = 1 + 0.8 * def_.implicitStrainLimit;
  const int nc = def_.columns, nr = def_.rows;
  const size_t n = x_.size();
  auto link = [&](uint32_t a, uint32_t b, double rest, std::vector<StrainLink>& out) {
    const double wa = w_[a], wb = w_[b];
    if (wa + wb == 0) return;
    const double max = limit * rest;
    out.push_back({a, b, max * max, target * rest, wa / (wa + wb), wb / (wa + wb)});
  };
  std::vector<char> pinColumn(size_t(nc), 0), pinRow(size_t(nr), 0);
  for (size_t i = 0; i < n; ++i) {
    if (w_[i] > 0) continue;
    pinColumn[i % size_t(nc)] = 1;
    pinRow[i / size_t(nc)] = 1;
  }
  // Rest distances along a row and a column (the grid is regular).
  const double du = def_.u.norm() / (nc - 1), dv = def_.v.norm() / (nr - 1);
  strainLevels_.clear();
  size_t nodes = n;
  const int maxStride = self_ ? 0 : 2 * (std::max(nc, nr) - 1);
  for (int stride = 2; stride < maxStride; stride *= 2) {
    StrainLevel level;
    for (int c = 0; c < nc; ++c)
      if (c % stride == 0 || c == nc - 1 || pinColumn[size_t(c)]) level.columns.push_back(c);
    for (int r = 0; r < nr; ++r)
      if (r % stride == 0 || r == nr - 1 || pinRow[size_t(r)]) level.rows.push_back(r);
    const size_t count = level.columns.size() * level.rows.size();
    if (4 * count > 3 * nodes) break;  // many pins: hardly coarser than the grid below
    nodes = count;
    for (int r : level.rows)
      for (size_t k = 0; k + 1 < level.columns.size(); ++k)
        link(uint32_t(Index(level.columns[k], r)), uint32_t(Index(level.columns[k + 1], r)),
             du * (level.columns[k + 1] - level.columns[k]), level.links);
    for (int c : level.columns)
      for (size_t k = 0; k + 1 < level.rows.size(); ++k)
        link(uint32_t(Index(c, level.rows[k])), uint32_t(Index(c, level.rows[k + 1])),
             dv * (level.rows[k + 1] - level.rows[k]), level.links);
    // Each fine column's coarse interval [coarse[k], coarse[k + 1]] and
    // its fraction of the way along it.
    auto below = [](const std::vector<int>& coarse, int fine, std::vector<int>& index,
                    std::vector<double>& fraction) {
      index.resize(size_t(fine));
      fraction.resize(size_t(fine));
      size_t k = 0;
      for (int c = 0; c < fine; ++c) {
        while (k + 2 < coarse.size() && coarse[k + 1] <= c) ++k;
        index[size_t(c)] = int(k);
        fraction[size_t(c)] = double(c - coarse[k]) / double(coarse[k + 1] - coarse[k]);
      }
    };
    below(level.columns, nc, level.columnBelow, level.columnFraction);
    below(level.rows, nr, level.rowBelow, level.rowFraction);
    strainLevels_.push_back(std::move(level));
  }
  std::reverse(strainLevels_.begin(), strainLevels_.end());
  // The finest: the structural constraints (MaxStretch's), in colour order.
  StrainLevel fine;
  for (const Constraint& c : constraints_)
    if (c.compliance == def_.stretchCompliance) link(c.a, c.b, c.rest, fine.links);
  strainLevels_.push_back(std::move(fine));
  strainBuilt_ = true;
}

void Cloth::LimitStrain(std::vector<Vec3>& x, std::vector<Vec3>& v, double h) {
  if (!strainBuilt_) BuildStrainLimiter();
  constexpr int kCoarsePasses = 2, kFinePasses = 2;  // a cycle's passes on each grid
  // One Gauss-Seidel pass; whether it shortened a link.
  auto pass = [&x](const std::vector<StrainLink>& links) {
    bool any = false;
    for (const StrainLink& l : links) {
      const Vec3 d = x[l.b] - x[l.a];
      const double len2 = d.squaredNorm();
      if (!(len2 > l.max2)) continue;
      const double len = std::sqrt(len2);
      const Vec3 corr = d * ((len - l.target) / len);
      x[l.a] += l.shareA * corr;
      x[l.b] -= l.shareB * corr;
      any = true;
    }
    return any;
  };
  strainX0_ = x;
  const int nc = def_.columns, nr = def_.rows;
  lastStrainCycles_ = 0;
  for (int cycle = 0; cycle < def_.implicitStrainIterations; ++cycle) {
    ++lastStrainCycles_;
    bool clean = false;
    for (int p = 0; p < kFinePasses && !clean; ++p) clean = !pass(strainLevels_.back().links);
    if (clean) break;
    for (size_t l = 0; l + 1 < strainLevels_.size(); ++l) {
      const StrainLevel& level = strainLevels_[l];
      strainLevelX0_ = x;
      bool any = false;
      for (int p = 0; p < kCoarsePasses && pass(level.links); ++p) any = true;
      if (!any) continue;
      // The particles between the nodes follow them.
      for (int r = 0; r < nr; ++r) {
        const int ri = level.rowBelow[size_t(r)];
        const double fr = level.rowFraction[size_t(r)];
        for (int c = 0; c < nc; ++c) {
          const size_t i = size_t(Index(c, r));
          const int ci = level.columnBelow[size_t(c)];
          const double fc = level.columnFraction[size_t(c)];
          if (((fc == 0 || fc == 1) && (fr == 0 || fr == 1)) || w_[i] == 0) continue;  // a node
          auto moved = [&](int cc, int rr) {
            const size_t k = size_t(Index(level.columns[size_t(cc)], level.rows[size_t(rr)]));
            return x[k] - strainLevelX0_[k];
          };
          x[i] += (1 - fr) * ((1 - fc) * moved(ci, ri) + fc * moved(ci + 1, ri)) +
                  fr * ((1 - fc) * moved(ci, ri + 1) + fc * moved(ci + 1, ri + 1));
        }
      }
    }
  }
  const double invH = 1 / h;
  for (size_t i = 0; i < x.size(); ++i) v[i] += invH * (x[i] - strainX0_[i]);
}

}  // namespace sylva::particles
