// Particles by the million: spray, snow, sparks, dust (the effects that
// Houdini's POP networks and Blender's particle systems run in single
// precision).
//
// System (system.h) is the general particle system: double precision, any
// force, five integrators, pair forces and implicit springs. At a million
// particles its step is bound by memory: position and velocity alone are 48
// bytes a particle in double, read and written every step. BulkSystem keeps
// the hot state in single precision, structure of arrays (px, py, pz, vx, vy,
// vz: 24 bytes a particle), and advances eight particles per AVX instruction.
// It does what such effects need and no more:
//   - uniform fields: gravity (an acceleration), linear and quadratic drag
//     relative to a uniform wind;
//   - symplectic Euler, the only integrator;
//   - every Collider kind and response (bounce with restitution and Coulomb
//     friction, resting and sliding contact, stick, kill), resolved in double
//     precision by the same code as System's (RespondToContacts);
//   - particles born from an Emitter (Append) and removed when dead
//     (RemoveDead), ids kept.
// Arithmetic is single precision (relative rounding about 6e-8 an
// operation); positions far from the origin are quantised accordingly (1 km
// away, to 61 micrometres). Use System where that matters, or for springs,
// cloth, flocking and the other integrators.
//
// Every particle's step depends on that particle alone, so a run is
// bit-identical for any thread count, and the AVX kernel and its scalar twin
// give the same bits (kernels.h).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
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

struct ParticleState;

// Structure of arrays in single precision.
struct BulkState {
  // hot
  std::vector<float> px, py, pz, vx, vy, vz;
  // cold
  std::vector<float> invMass;  // 1/kg; 0: pinned (immovable); NaN: a bad mass (Add)
  // The clock's time at birth (s): a particle's age is time - birth, so a
  // step does not touch it.
  std::vector<float> birth;
  std::vector<float> lifetime;  // s of age
  std::vector<Vec3f> color;
  std::vector<float> radius;  // m, >= 0: the ball every collider sees, and the drawn size
  std::vector<uint32_t> id;
  uint32_t nextId = 0;
  double time = 0;  // the clock (s), advanced by BulkSystem::Step
  // The first particle added with a bad mass (particle_core.h), for Step.
  MassRecord massRecord;

  size_t size() const { return px.size(); }
  double age(size_t i) const { return time - double(birth[i]); }
  bool dead(size_t i) const { return age(i) >= double(lifetime[i]); }
  // Adds a particle born now (rounded to single precision), of radius 0 (a
  // point), and returns its id. mass in (0, 1e30] kg; any other mass (0,
  // negative, NaN) leaves the particle still and makes the next
  // BulkSystem::Step an error naming it: a mass of 0 does not mean
  // immovable, pinning does.
  uint32_t Add(const Vec3& p, const Vec3& v, double mass = 1, double lifetime = 1e30);
  // Adds an immovable particle at rest and returns its id.
  uint32_t AddPinned(const Vec3& p, double lifetime = 1e30);
  void Pin(size_t i) { invMass[i] = 0; }
  bool pinned(size_t i) const { return invMass[i] == 0; }
  Vec3 position(size_t i) const { return Vec3(px[i], py[i], pz[i]); }
  Vec3 velocity(size_t i) const { return Vec3(vx[i], vy[i], vz[i]); }
  void SetPosition(size_t i, const Vec3& p);
  void SetVelocity(size_t i, const Vec3& v);
  void Reserve(size_t n);
  // Every per-particle array of floats (all but color and id).
  std::array<std::vector<float>*, 10> FloatArrays() {
    return {&px, &py, &pz, &vx, &vy, &vz, &invMass, &birth, &lifetime, &radius};
  }
};

// The uniform fields acting on every movable particle. Ranges (checked by
// Validate, which BulkSystem::Step calls first):
struct BulkFields {
  Vec3 gravity{0, 0, 0};  // acceleration, m/s^2, each component within +-1e12
  // Drag force -(linear + quadratic |u|) u, with u = v - wind (N); each 0..1e12.
  double linearDrag = 0, quadraticDrag = 0;
  Vec3 wind{0, 0, 0};  // m/s, each component within +-1e12
};

// The first field of `fields` outside its range, or ok.
Status Validate(const BulkFields& fields);

class BulkSystem {
 public:
  explicit BulkSystem(int threads = 1);
  ~BulkSystem();
  BulkSystem(const BulkSystem&) = delete;
  BulkSystem& operator=(const BulkSystem&) = delete;

  BulkState state;
  BulkFields fields;
  uint64_t steps = 0;
  double time() const { return state.time; }
  double maxMagnitude = 1e12;  // a coordinate or speed beyond this is an explosion, 1e-30..1e300

  // 0 = every hardware thread.
  void SetThreads(int threads);
  // Runs on a shared `pool` (not owned, outliving the system); null: serial.
  void UsePool(ThreadPool* pool);
  int threads() const;
  // Adds a collider that passes Validate(Collider), else its Diagnostic.
  [[nodiscard]] Status AddCollider(Collider c);
  const std::vector<Collider>& colliders() const { return colliders_; }

  // One symplectic Euler step of length h: fields, integration, collisions,
  // ageing. h in (0, 1e6] s; `fields` and maxMagnitude are checked first
  // (a Diagnostic, nothing moves). A coordinate or speed beyond maxMagnitude
  // (or not finite, in any component), contacts still unresolved after
  // kMaxContacts, or a radius that is negative, not finite or beyond
  // maxMagnitude in a step with colliders (they take it as given), is
  // reported with the step and the particle's id, and the system then
  // refuses to step again.
  [[nodiscard]] Status Step(double h);

  // Appends particles [begin, size) of `born` (an Emitter's output) with
  // their ages, ids, colours, sizes and pinned flags (a bad mass of `born`
  // is reported by the next Step); nextId moves past the largest id. The
  // arrays grow geometrically (appending a few particles a step costs
  // amortised O(1) a particle). Returns the number appended.
  size_t Append(const ParticleState& born, size_t begin = 0);
  // Removes particles whose age has reached their lifetime (`dead`), keeping the
  // order (and ids) of the living. Returns the number removed.
  size_t RemoveDead();

  // Kinetic energy, sum of |v|^2 / (2 w) over movable particles.
  double KineticEnergy() const;
  // Fingerprint of positions and velocities (bit patterns).
  uint64_t Hash() const;

  // Whether particles remember the mesh triangles they lie on between
  // steps (MeshMemo; on by default): off, every mesh query is a full one.
  // The same answers either way (tests compare them), only slower.
  void SetMeshMemos(bool on) {
    meshMemos_ = on;
    memos_.clear();
  }

  // Whether a particle at an exact fixed point of the step sleeps (on by
  // default; see Still below): off, every particle takes the whole step.
  // The same bits either way (tests compare them), only slower.
  void SetSleeping(bool on) {
    sleeping_ = on;
    asleep_.clear();
    still_.clear();
  }
  // Particles that slept (skipped the step) in the last Step.
  size_t sleepers() const { return sleepers_.load(std::memory_order_relaxed); }

  // Chooses the vector kernel (tests compare AVX with its scalar twin).
  // AVX only where the processor has it. restLanes: the lanes of the
  // resting-floor path with AVX: 4 (a kernel after the advance), or 8 where
  // the processor has AVX-512 (the advance, the floor's candidates and its
  // resting contacts in one pass); 0: the widest it runs. Same bits.
  void SetKernel(kernels::Kernel k, int restLanes = 0) {
    kernel_ = k == kernels::Kernel::kAvx ? kernels::Best() : kernels::Kernel::kScalar;
    restLanes_ = kernel_ == kernels::Kernel::kScalar ? 0
                 : restLanes == 0                    ? kernels::RestLanes()
                                                     : std::min(restLanes, kernels::RestLanes());
  }

 private:
  void StepRange(size_t begin, size_t end, double h, const kernels::BulkParams& q, bool sleep);
  Status Fault();

  std::vector<Collider> colliders_;
  PoolChoice pools_;
  kernels::Kernel kernel_ = kernels::Best();
  int restLanes_ = kernels::RestLanes();
  FaultLatch faults_;
  // What each particle remembers of the mesh it lies on (MeshMemo), where a
  // collider is a mesh; empty otherwise.
  std::vector<MeshMemo> memos_;
  bool meshMemos_ = true;
  // Sleeping, exact. A particle's step is a function of its six floats,
  // its radius and inverse mass and of the step's inputs alone (fields, h,
  // the magnitude limit, colliders; the memos change only how fast the
  // answer comes): where the last step, through the contact response, left
  // all six unchanged (a flake lying on a mesh), the same inputs give the
  // same step again. still_[i] records the particle's floats then (32
  // bytes), asleep_[i] that it is valid; while the step's inputs (key_) do
  // not change and no collider moves, a particle whose floats, radius and
  // inverse mass equal its record skips the collision work and keeps its
  // state: the bits the whole step would give. A change of the inputs
  // wakes every particle.
  struct Still {
    float s[6];  // px, py, pz, vx, vy, vz
    float radius, invMass;
  };
  std::vector<Still> still_;
  std::vector<uint8_t> asleep_;
  std::array<uint64_t, 8> key_{};
  bool sleeping_ = true;
  std::atomic<size_t> sleepers_{0};
};

}  // namespace sylva::particles
