// Newtonian particles (Angel & Shreiner ch. 9; Baraff & Witkin, "Physically
// Based Modeling", SIGGRAPH course notes).
//
// State is structure of arrays, hot fields apart from cold ones:
//   hot   position, velocity            (48 bytes a particle)
//   cold  mass, inverse mass, age, lifetime, colour, radius, id
// Each step computes every force first, for all particles, then advances the
// state with the chosen integrator, then resolves collisions. Forces are
// evaluated on whatever positions and velocities the integrator asks about
// (RK stages), never on the stored state directly.
//
// Threads. Forces whose value on particle i depends only on particle i
// (gravity, drag, wind, fields, anchors: `LocalForce`) are evaluated chunk by
// chunk, fused with the integration and the collision response into one pass
// over memory, on every thread of the system's pool. Pair forces (springs,
// grids, flocking) are evaluated first, for all particles; those that loop
// over particles gather per particle and may use the pool too. Every result
// is written by exactly one thread in an order fixed by the particle index,
// so a run is bit-identical whatever the thread count.
//
// Faults. A step that leaves a non-finite value (in any of x, y, z of a
// position or velocity) or a coordinate or speed beyond
// `System::maxMagnitude`, or a particle whose contacts are still unresolved
// after kMaxContacts (collider.h), or a particle whose radius is negative,
// not finite or beyond maxMagnitude in a step with colliders or particle
// collisions (they would take it as given), returns an error naming the
// step and the particle id; the system then refuses to step again. Implicit Euler also
// reports a system that is not positive definite (nothing moves; a smaller
// step may succeed).
//
// Warnings. A step whose particle collisions (EnableParticleCollisions)
// form a gas that did not converge within pairMaxPasses velocity passes
// returns a Diagnostic of severity kWarning naming the step: the step was
// taken and the system steps on (a Status that is not ok: check
// error().severity).
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/math.h"
#include "core/parallel.h"
#include "core/status.h"
#include "particles/collider.h"
#include "particles/kernels.h"
#include "particles/particle_core.h"

namespace sylva::particles {

class NeighbourGrid;
struct PairWork;

struct ParticleState {
  // hot
  std::vector<Vec3> position, velocity;
  // cold
  std::vector<double> mass, invMass, age, lifetime;
  std::vector<Vec3f> color;
  // Metres, >= 0: the particle is a ball of this radius to every collider
  // (its centre stays at least this far from a surface) and its drawn size.
  std::vector<float> radius;
  std::vector<uint32_t> id;
  uint32_t nextId = 0;
  // The time and step number forces are evaluated at (set by the system).
  double time = 0;
  uint64_t step = 0;

  // The first particle added with a bad mass (particle_core.h), for Step.
  MassRecord massRecord;

  size_t size() const { return position.size(); }
  // Adds a particle of radius 0 (a point: set radius.back() for a ball) and
  // returns its id. mass in (0, 1e30] kg; any other mass (0, negative, NaN)
  // leaves the particle still and makes the next System::Step an error
  // naming it: a mass of 0 does not mean immovable, pinning does.
  uint32_t Add(const Vec3& p, const Vec3& v, double mass = 1, double lifetime = 1e300);
  // Adds an immovable particle (pinned, of mass `mass` kg for the forces
  // that ask, at rest) and returns its id.
  uint32_t AddPinned(const Vec3& p, double mass = 1, double lifetime = 1e300);
  // A pinned particle does not move: its inverse mass is 0, its mass kept.
  // Unpin gives back the inverse of its mass (a pinned particle of a bad
  // mass stays an error until it has a mass in range).
  void Pin(size_t i) { invMass[i] = 0; }
  void Unpin(size_t i) { invMass[i] = InverseMassOf(mass[i], id[i], &massRecord); }
  bool pinned(size_t i) const { return invMass[i] == 0; }
};

// A force adds to f[i] (newtons) for every particle, given positions x and
// velocities v (of size n) and the particles' cold data in `s`.
class Force {
 public:
  virtual ~Force() = default;
  virtual void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const = 0;
  // True for a LocalForce (f[i] depends on particle i alone).
  virtual bool local() const { return false; }
  // The implicit solver linearises about (x, v) once a step: it calls
  // PrepareJacobian(x, v) first, then the products and the diagonal at the
  // same x and v. A force may cache what does not depend on p here.
  virtual void PrepareJacobian(const ParticleState&, const Vec3* /*x*/, const Vec3* /*v*/) {}
  // Matrix-free Jacobian product for the implicit solver:
  //   y += cx (df/dx) p + cv (df/dv) p.
  // Forces that do not override it are treated explicitly by that solver.
  virtual void AddJacobianProduct(const ParticleState&, const Vec3* /*x*/, const Vec3* /*v*/,
                                  double /*cx*/, double /*cv*/, const Vec3* /*p*/,
                                  Vec3* /*y*/) const {}
  // The diagonal of the same operator, per axis (the CG preconditioner).
  virtual void AddJacobianDiagonal(const ParticleState&, const Vec3* /*x*/, const Vec3* /*v*/,
                                   double /*cx*/, double /*cv*/, Vec3* /*diag*/) const {}
  // Whether the force fits state `s`: every particle index it holds is below
  // s.size(). System::Step asks once a step (O(1) for the library's forces),
  // before any work, so an index out of range is a Diagnostic, never a
  // write past the end.
  virtual Status Check(const ParticleState& /*s*/) const { return {}; }
  // After System::RemoveDead: newIndex[i] is the new index of the particle
  // that was at i, or kRemoved. A force that names particles follows them
  // and drops what named a removed one.
  virtual void Renumber(const std::vector<uint32_t>& /*newIndex*/) {}
  // The pool the force runs on: the system sets it to its own before every
  // step and clears it when the force is removed or the system destroyed,
  // so a force kept (shared_ptr) after its system never uses a freed pool.
  void set_pool(ThreadPool* pool) { pool_ = pool; }
  ThreadPool* pool() const { return pool_; }

 protected:
  ThreadPool* pool_ = nullptr;
};

// A force on each particle that depends on that particle alone. The system
// calls AccumulateRange on chunks [begin, end), in parallel; f[k] is the
// force on particle begin + k, while x and v are indexed by particle.
class LocalForce : public Force {
 public:
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const final {
    AccumulateRange(s, x, v, f, 0, s.size());
  }
  bool local() const final { return true; }
  virtual void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f,
                               size_t begin, size_t end) const = 0;
};

// Constant acceleration g for every movable particle (f = m g); each
// component within +-1e12 m/s^2 (Check, on every step, says otherwise).
class Gravity : public LocalForce {
 public:
  explicit Gravity(const Vec3& g) : g_(g) {}
  // Changes g; the next step checks it.
  void set_g(const Vec3& g) { g_ = g; }
  const Vec3& g() const { return g_; }
  Status Check(const ParticleState& s) const override;
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override;

 private:
  Vec3 g_;
};

// Drag: f = -k1 v - k2 |v| v (linear and quadratic); k1, k2 0..1e12
// (Check, on every step, says otherwise).
class Drag : public LocalForce {
 public:
  Drag(double linear, double quadratic = 0) : k1_(linear), k2_(quadratic) {}
  // Changes the coefficients; the next step checks them.
  void Set(double linear, double quadratic = 0) { k1_ = linear, k2_ = quadratic; }
  Status Check(const ParticleState& s) const override;
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override;
  void AddJacobianProduct(const ParticleState& s, const Vec3* x, const Vec3* v, double cx,
                          double cv, const Vec3* p, Vec3* y) const override;

 private:
  double k1_, k2_;
};

// Damped Hooke springs between particle pairs (Angel & Shreiner 9.3):
// with d = p_a - p_b, f_a = -[ks(|d| - rest) + kd (d'.d)/|d|] d/|d|, f_b = -f_a.
//
// Threads. The springs are coloured greedily (no two springs of a colour
// share a particle; springs of a particle with more than 64 colours in use
// go to a last, serial group), and every pass runs colour by colour, each
// colour in parallel: the sums on a particle are made in the same order
// whatever the thread count.
class Springs : public Force {
 public:
  struct Spring {
    uint32_t a, b;
    double rest, ks, kd;
  };
  // A spring between particles a != b, rest length 0..1e12 m, stiffness ks
  // 0..1e12 N/m, damping kd 0..1e12 N s/m; anything else (NaN included) is
  // a Diagnostic and adds nothing. The indices are checked against the
  // state by Check, on every System::Step.
  [[nodiscard]] Status Add(uint32_t a, uint32_t b, double rest, double ks, double kd);
  // Removes every spring.
  void Clear();
  // Follows System::RemoveDead: a spring joins the same two particles
  // (stable ids) at their new indices; one with a removed end goes.
  void Renumber(const std::vector<uint32_t>& newIndex) override;
  Status Check(const ParticleState& s) const override;
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;
  // Baraff & Witkin's spring Jacobian, with the transverse term clamped at
  // zero for compressed springs so the system matrix stays positive definite:
  //   df_a/dx_a = -[kl u u' + kt I],  kt = ks max(0, 1 - rest/|d|), kl = ks - kt
  //   df_a/dv_a = -kd u u'
  // PrepareJacobian caches u, kt and kl a spring; products at the same
  // positions array use the cache until the next PrepareJacobian (at any
  // other array they linearise themselves), and so does the one Accumulate
  // that follows it.
  void PrepareJacobian(const ParticleState& s, const Vec3* x, const Vec3* v) override;
  void AddJacobianProduct(const ParticleState& s, const Vec3* x, const Vec3* v, double cx,
                          double cv, const Vec3* p, Vec3* y) const override;
  void AddJacobianDiagonal(const ParticleState& s, const Vec3* x, const Vec3* v, double cx,
                           double cv, Vec3* diag) const override;
  const std::vector<Spring>& springs() const { return springs_; }
  // Colour groups of the last pass (the serial group counts as one).
  size_t colourCount() const { return colourStart_.empty() ? 0 : colourStart_.size() - 1; }

 private:
  // A spring in colour order with its linearisation.
  using Linear = kernels::SpringLinear;
  void Colour() const;
  // fn(spring index in colour order j, spring) for every spring, colour by
  // colour.
  template <typename Fn>
  void ForColours(Fn&& fn) const;
  static Linear Linearise(const Spring& sp, const Vec3* x, double* length);
  std::vector<Spring> springs_;
  uint32_t maxIndex_ = 0;       // the largest particle index of a spring
  std::vector<Linear> linear_;  // from PrepareJacobian at preparedX_, colour order
  std::vector<double> length_;  // and the springs' lengths
  const Vec3* preparedX_ = nullptr;
  // The next Accumulate at preparedX_ (the implicit solver's, right after
  // PrepareJacobian) takes lengths and directions from linear_; only that
  // one, since the positions may change after it.
  mutable bool accumulateCached_ = false;
  // Colour order: springs order_[colourStart_[c] .. colourStart_[c + 1]);
  // the last group is serial when serialGroup_.
  mutable std::vector<uint32_t> order_;
  mutable std::vector<size_t> colourStart_;
  mutable bool serialGroup_ = false;
  mutable size_t colouredSprings_ = SIZE_MAX;
  mutable size_t particles_ = 0;                  // 1 + the largest particle index of a spring
  mutable std::vector<kernels::Point4> p4_, y4_;  // the product's padded operands
  kernels::Kernel kernel_ = kernels::Best();
};

// A user force as a callable (evaluated for all particles at once).
class ForceFunction : public Force {
 public:
  using Fn = std::function<void(const ParticleState&, const Vec3*, const Vec3*, Vec3*)>;
  explicit ForceFunction(Fn fn) : fn_(std::move(fn)) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override {
    fn_(s, x, v, f);
  }

 private:
  Fn fn_;
};

enum class Integrator {
  kExplicitEuler,    // x += h v, v += h a(x, v): first order, unstable for stiff springs
  kSymplecticEuler,  // v += h a(x, v), x += h v_new: first order, bounded energy error
  kMidpoint,         // RK2 (improved Euler): second order, two evaluations
  kRK4,              // classical Runge-Kutta: fourth order, four evaluations
  kImplicitEuler,    // backward Euler linearised once (Baraff & Witkin 1998), CG solve
};

// A plane collider in the shape the first examples use; see Collider for the
// other shapes. `friction` is Coulomb's coefficient mu.
struct Plane {
  Vec3 point{0, 0, 0};
  Vec3 normal{0, 1, 0};  // unit
  double restitution = 1;
  double friction = 0;
};

// Adaptive Dormand-Prince RK45: error per component against
// atol + rtol * |value|, over positions and velocities.
struct AdaptiveOptions {
  double rtol = 1e-6, atol = 1e-9;
  double minStep = 1e-12;
  int maxSteps = 1000000;  // per call
};
struct AdaptiveStats {
  int accepted = 0, rejected = 0;
  double lastStep = 0;  // the step the controller would try next
  double maxError = 0;  // largest accepted error norm (<= 1)
};

// Implicit Euler's conjugate-gradient solve.
struct SolveStats {
  int iterations = 0;
  double residual = 0;  // |r| / |b| at the end
};

// Names a force of a System (AddForce): unique over the process, so a
// handle of another system or of a removed force names nothing.
struct ForceHandle {
  uint64_t id = 0;  // 0: none
};

class System {
 public:
  explicit System(int threads = 1);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  ParticleState state;
  double time = 0;
  uint64_t steps = 0;
  double maxMagnitude = 1e12;  // a coordinate or speed beyond this is an explosion, 1e-300..1e300
  // Implicit Euler's CG: stop at this relative residual or iteration count.
  double cgTolerance = 1e-10;
  int cgMaxIterations = 200;
  // Particle collisions: the most velocity passes a step with no resting
  // contact (a gas) runs to meet every collision's target speed
  // (pairs.cpp), 16..1e7; a step that reaches it keeps what the passes
  // gave and returns a warning.
  int pairMaxPasses = 1024;

  // 0 = every hardware thread. Starts a pool of the system's own.
  void SetThreads(int threads);
  // Chooses the vector kernels (kernels.h; tests compare them with their
  // scalar twins): kAvx takes the widest this processor runs.
  void SetKernel(kernels::Kernel k) {
    kernel_ = k == kernels::Kernel::kAvx ? kernels::Best() : kernels::Kernel::kScalar;
  }
  // Runs on `pool` (not owned; it must outlive the system), shared with the
  // rest of the process (core/parallel.h SharedPool); null: serial. The
  // results are the same as with SetThreads of any count.
  void UsePool(ThreadPool* pool);
  int threads() const;
  // Forces. AddForce returns the force's handle (the system shares the
  // force: the caller may keep its pointer and change the force's
  // parameters between steps, each checked by the next step). Forces are
  // evaluated in the order added; ReplaceForce keeps the place.
  // RemoveForce and ReplaceForce with a handle of a removed force, of
  // another system or a default one are Diagnostics and change nothing.
  ForceHandle AddForce(std::shared_ptr<Force> f);
  [[nodiscard]] Status ReplaceForce(ForceHandle handle, std::shared_ptr<Force> f);
  [[nodiscard]] Status RemoveForce(ForceHandle handle);
  // The force of `handle`, or null when it names none of this system's.
  Force* force(ForceHandle handle) const;
  size_t forceCount() const { return forces_.size(); }
  // Removes the particles whose age has reached their lifetime, keeping the
  // order and ids of the living, and renumbers every force's particles
  // (Force::Renumber: springs follow their particles, those of a removed
  // one go). Returns the number removed.
  size_t RemoveDead();
  // Adds a collider that passes Validate(Collider), else its Diagnostic.
  // One with a velocity moves by h times it after every step (colliders()
  // gives where they are).
  [[nodiscard]] Status AddCollider(Collider c);
  // Replaces collider `index` (a solid whose shape changes, such as a cloth
  // rebuilt each step); the same checks as AddCollider, and an index past
  // the colliders is an error.
  [[nodiscard]] Status SetCollider(size_t index, Collider c);
  const std::vector<Collider>& colliders() const { return colliders_; }
  [[nodiscard]] Status AddPlane(const Plane& p) {
    return AddCollider(
        Collider::Plane(p.point, p.normal).Restitution(p.restitution).Friction(p.friction));
  }
  // Particles as balls that collide with each other, with the given
  // restitution, resolved after every step (pairs.cpp): each a ball of its
  // own state.radius, or of `radius` where that is 0. Contacts are swept
  // (balls do not pass through each other however fast), solved in
  // parallel and bit-identical for any thread count. radius 1e-12..1e12 m,
  // restitution 0..1, else a Diagnostic.
  [[nodiscard]] Status EnableParticleCollisions(double radius, double restitution);

  // Accelerations for positions x and velocities v (all particles).
  void Accelerations(const Vec3* x, const Vec3* v, Vec3* a) const;
  // One step of length h: forces, integration, collisions, ageing.
  // h in (0, 1e6] s (NaN, 0, negative: a Diagnostic, nothing moves); the
  // settings above (maxMagnitude 1e-300..1e300, cgTolerance 0..1,
  // cgMaxIterations 1..1e7), every force's Check and the masses (a bad
  // mass given to ParticleState::Add, see there) are verified first.
  // Faults are reported as described at the top of this file.
  [[nodiscard]] Status Step(double h, Integrator integrator);
  // Advances by dt with adaptive Dormand-Prince RK45 substeps: dt as h
  // above; options rtol 0..1, atol 0..1e12 (not both 0), minStep
  // 1e-300..dt s, maxSteps 1..1e9.
  [[nodiscard]] Status StepAdaptive(double dt, const AdaptiveOptions& options,
                                    AdaptiveStats* stats = nullptr);
  const SolveStats& lastSolve() const { return solve_; }
  // Kinetic energy, sum of m |v|^2 / 2 over movable particles.
  double KineticEnergy() const;
  // Fingerprint of positions and velocities (bit patterns).
  uint64_t Hash() const;

 private:
  template <typename Fn>
  void ForChunks(size_t n, Fn&& fn) const;
  void NonLocalForces(const Vec3* x, const Vec3* v) const;
  void StagePoint(double c, const Vec3* dx, const Vec3* dv, Vec3* out) const;
  void LocalForcesInto(size_t begin, size_t end, const Vec3* x, const Vec3* v, Vec3* fc) const;
  // Collisions, ageing and the fault check for particle i, then stores it.
  void Finish(size_t i, const Vec3& x0, const Vec3& v0, Vec3 x1, Vec3 v1, double h);
  void Collide(size_t i, Vec3 a, Vec3 va, Vec3& x, Vec3& v, double h);
  Status ImplicitEuler(double h);
  // The fault of a non-finite vector `a` of the implicit solve (naming its
  // first non-finite particle).
  Status NonFiniteSolve(const char* what, const Vec3* a, int iteration);
  // Sum of fn(begin, end) over the fixed chunks of [0, n) (1024 elements,
  // a multiple of 4), added in chunk order: the same bits for any thread
  // count.
  template <int K, typename Fn>
  std::array<double, K> SumChunks(size_t n, Fn&& fn) const;
  void ParticleCollisions(double h);
  // Holds a pile up: its overlaps resolved in order of height along `up`
  // (pairs.cpp).
  void SupportSweep(const Vec3& up, double h);
  // Saves the state at the start of a step for the pair contacts.
  void SavePairStart();
  // Moves every moving collider by h times its velocity (after a step).
  void MoveColliders(double h);
  // At the start of a step with colliders or particle collisions: flags
  // the first particle whose radius is bad (BadRadiusIn); the step's fault
  // scan reports it.
  void FlagBadRadii();
  Status CheckFaults(const char* what);
  // The warning of a step whose gas contacts reached pairMaxPasses (pairs.cpp).
  Status PairPassesWarning(const char* what) const;
  Status CheckStep(const char* what, double h);

  // Hands the pool to every force (before a step) or takes it back.
  void LendPool();
  void TakeBackPool(Force& f) const;
  size_t ForceIndex(ForceHandle handle) const;  // SIZE_MAX: none
  Status HandleError(const char* what, ForceHandle handle) const;
  void UpdateLocality();

  std::vector<std::shared_ptr<Force>> forces_;
  std::vector<uint64_t> forceIds_;  // forces_[k]'s handle
  std::vector<uint32_t> remap_;     // RemoveDead's new indices
  std::vector<Collider> colliders_;
  PoolChoice pools_;
  ThreadPool* pool_ = nullptr;  // pools_.pool(): the pool in use (own or shared), null: serial
  bool hasNonLocal_ = false;
  double pairRadius_ = 0, pairRestitution_ = 1;
  std::unique_ptr<PairWork> pairWork_;  // pairs.h: the pair contacts' arrays
  FaultLatch faults_;
  SolveStats solve_;
  double adaptiveStep_ = 0;
  // Scratch (sized once per particle count).
  mutable std::vector<Vec3> f_, k_[14], x_, v_, cg_[6];
  std::vector<double> mass3_;   // the implicit solver's mass per coordinate
  std::vector<size_t> pinned_;  // and its immovable particles
  kernels::Kernel kernel_ = kernels::Best();
};

}  // namespace sylva::particles
