// Cloth: a rectangular grid of particles held by structural, shear and bend
// distance constraints, solved with XPBD (Macklin, Muller & Chentanez,
// "XPBD: position-based simulation of compliant constrained dynamics",
// MIG 2016) in substeps (Macklin et al., "Small steps in physics
// simulation", SCA 2019).
//
// Design notes. Each substep predicts positions from velocities and external
// accelerations (wind is evaluated once a frame), then projects every
// constraint `iterations` times, colour by colour (a greedy colouring makes
// the constraints of one colour independent, so they run in parallel and
// the result is the same for any thread count), with its
// compliance alpha (inverse stiffness, m/N): the Lagrange multiplier update
//   dl = (-C - alpha~ l) / (w_i + w_j + alpha~),  alpha~ = alpha / h^2
// makes the stiffness independent of the iteration count and the step, so a
// hanging mass settles at the extension m g alpha however many iterations
// are used. Velocities are (x - x_prev) / h. Pinned particles have inverse
// mass 0 and never move.
//
// Wind acts on each triangle (area A, unit normal n) through the air's
// speed relative to it, u = wind - mean corner velocity, with th the angle
// between n and u. Drag pulls along u, lift pushes across it (in the plane
// of n and u), skin friction pulls along the triangle:
//   drag     c_d A |u| cos^2 th
//   lift     c_l A |u| cos th sin th
//   friction c_f A (u - (n.u) n)
// All three are linear in |u|. With c_d = c_l drag and lift add up to
// A (n.u) n, the pressure on a flat plate, which is the default.
//
// The wind may vary over the cloth (StepInWindField): each triangle
// feels the air at its centroid (ClothWind.WindFieldActsOnEachTriangleWhereItIs).
// In a uniform wind these per-triangle forces make a flag flutter where a
// drag on each particle leaves it still
// (ClothWind.FlagFluttersInUniformWindWhereParticleDragGoesStill).
//
// Contacts (cloth_collision.h): colliders of collider.h (plane, sphere,
// box, polygon, mesh, capsules) with Coulomb friction, and the cloth with
// itself when ClothDef::thickness > 0. XPBD resolves them on positions
// after the constraints of every substep; the implicit solver passes the
// colliders to its particle System (its contact response, restitution
// included) and runs the self-collision pass after each implicit step.
//
// The implicit solver (ClothDef::solver = kImplicit) turns every constraint
// into a damped spring of stiffness 1/compliance, at most
// `implicitStiffness`, and takes backward-Euler steps (Baraff & Witkin
// 1998) with `cgIterations` of matrix-free conjugate gradients: larger
// steps, softer cloth, more numerical damping. One linearised step of
// 1/10 s is far from the nonlinear solution (a 32 x 32 cloth hanging from
// two corners stretches past 20 %); strain limiting after each step
// (implicitStrainLimit, Provot, "Deformation constraints in a mass-spring
// model to describe rigid cloth behavior", Graphics Interface 1995), on
// the cloth's own links and then on coarser grids of it, holds 32 x 32,
// 64 x 64 and 100 x 100 sheets hanging from two corners at 1/10 s to the
// default 10 % (ClothImplicit.StrainLimitingHoldsTenPercent*).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/math.h"
#include "core/parallel.h"
#include "particles/collider.h"
#include "particles/system.h"
#include "particles/xpbd.h"

namespace sylva::particles {
namespace clothcontact {
class SelfCollision;
}

enum class ClothSolver { kXPBD, kImplicit };

// Ranges (Validate rejects anything outside, NaN included, naming the field
// and the value):
struct ClothDef {
  int columns = 20, rows = 20;    // particles along u and v, each 2..10000, columns * rows <= 1e7
  Vec3 origin{0, 0, 0};           // corner (0, 0), m, each component within +-1e12
  Vec3 u{1, 0, 0}, v{0, -1, 0};   // edges of the whole cloth, m, within +-1e12, not parallel
  double mass = 1;                // total, kg, 1e-12..1e12
  double stretchCompliance = 0;   // m/N, 0..1e12: 0 = inextensible
  double shearCompliance = 1e-4;  // m/N, 0..1e12
  double bendCompliance = 1e-2;   // m/N, 0..1e12
  // Substeps x iterations decide how stiff "inextensible" really is: more
  // of either stretches less (Cloth.MoreSubstepsAndIterationsStretchLess:
  // a 30 x 30 sheet hanging from two corners without tethers).
  int substeps = 10;   // 1..10000
  int iterations = 1;  // per substep, 1..10000
  double damping = 0;  // fraction of velocity removed per second, 0..1e6
  // Air force coefficients, N per (m^2 * m/s); see the notes above.
  double windDrag = 1.0;    // c_d, along the relative air speed, 0..1e6
  double windLift = 1.0;    // c_l, across it, -1e6..1e6
  double windFriction = 0;  // c_f, along the triangle, 0..1e6
  std::vector<int> pinned;  // particle indices (row * columns + column), each 0..columns * rows - 1
  // Long-range attachments: tethers from every particle to its two nearest
  // pins, at their rest distance (XPBD only: the implicit solver ignores
  // them).
  bool longRangeAttachments = true;
  // Self-collision: two particles that were farther apart than `thickness`
  // at rest are kept at least that far apart, m, 0..1e12 (0: off). A sheet
  // cannot slip through itself between particles when thickness is at
  // least the diagonal gap of a cell, spacing / sqrt(2), and no particle
  // moves more than `thickness` in a substep.
  double thickness = 0;
  double selfFriction = 0.3;  // Coulomb mu between layers that touch, 0..1e3
  int threads = 1;            // 0..256, 0 = every hardware thread
  // When set, the cloth runs on this pool (shared with the process, not
  // owned, outliving the cloth) and `threads` is not used.
  ThreadPool* pool = nullptr;
  ClothSolver solver = ClothSolver::kXPBD;
  // Implicit solver only.
  double implicitStiffness = 2000;  // N/m for constraints of compliance 0, 1e-12..1e12
  double implicitDamping = 0.02;    // N s/m along each spring, 0..1e12
  int implicitSubsteps = 1;         // backward-Euler steps per Step, 1..10000
  // Strain limiting after each implicit step (Provot 1995): structural
  // constraints stretched more than this fraction are shortened (to 80 %
  // of it), on the cloth's own links first and then on coarser grids of
  // it (see LimitStrain in cloth.cpp), in cycles until a pass finds none past
  // the limit, at most `implicitStrainIterations` cycles; the velocities
  // take the correction. 0..1e6; 0 = off.
  double implicitStrainLimit = 0.1;
  int implicitStrainIterations = 200;  // cycles, 1..100000
  int cgIterations = 20;               // 1..100000
};

// The first field of `def` outside its range, or ok.
Status Validate(const ClothDef& def);

class Cloth {
 public:
  // A cloth of a valid definition, or the Diagnostic of Validate. The cloth
  // stays where it was made (its forces point back at it), hence the pointer.
  static Expected<std::unique_ptr<Cloth>> Create(const ClothDef& def);
  ~Cloth();
  Cloth(const Cloth&) = delete;
  Cloth& operator=(const Cloth&) = delete;
  // One frame of dt seconds. dt in (0, 1e6] s, gravity (m/s^2) and wind
  // (m/s) each component within +-1e12: otherwise a Diagnostic and nothing
  // moves. A particle whose position or velocity is not finite, before the
  // frame (the caller moved it there) or after it, is reported with the
  // frame number and its index; the cloth then refuses to step again. The
  // implicit solver's failures (a right-hand side or product that is not
  // finite, a system that is not positive definite) come back the same way,
  // with the frame and the substep.
  [[nodiscard]] Status Step(double dt, const Vec3& gravity, const Vec3& wind = Vec3::Zero());
  // The air's velocity (m/s) at a point: evaluated at each triangle's
  // centroid once a frame (XPBD) or at each force evaluation (implicit), on
  // the cloth's threads, so it must be safe to call concurrently. A
  // non-finite value is reported like a non-finite particle.
  using WindField = std::function<Vec3(const Vec3& x)>;
  [[nodiscard]] Status StepInWindField(double dt, const Vec3& gravity, const WindField& wind);
  // A collider (Validate'd: a Diagnostic and nothing added if it is bad).
  // The cloth keeps its contacts inelastic (XPBD: restitution is not used),
  // with the collider's friction; a particle that touches a kStick collider
  // becomes immovable, as a pin; kKill is an error (a cloth particle cannot
  // die).
  // `thickness` (m, 0..1e3): how far the cloth's particles keep from it
  // (the XPBD solver; the implicit one keeps none). A sheet met from
  // either side, such as another cloth, needs some.
  Status AddCollider(Collider c, double thickness = 0);
  // Replaces collider `index` (another cloth, rebuilt each step), keeping
  // its thickness; the same checks as AddCollider.
  Status SetCollider(size_t index, Collider c);
  const std::vector<Collider>& colliders() const { return colliders_; }
  // An extra force on each free particle, N: f(i, x, v) for particle i at
  // x with velocity v (drag, attractors, noise). Evaluated with the wind
  // (once a frame for XPBD), on the cloth's threads: it must be safe to call
  // concurrently. Empty: none.
  using ForceField = std::function<Vec3(size_t i, const Vec3& x, const Vec3& v)>;
  void SetExternalForce(ForceField f) { externalForce_ = std::move(f); }
  // Mass of one particle, kg (ClothDef::mass / particles).
  double particleMass() const { return def_.mass / double(x_.size()); }
  // Particles that a collider or the self-collision moved in the last
  // frame, summed over the substeps (implicit: the self-collision's only;
  // its particle System handles the colliders).
  size_t lastContacts() const { return lastContacts_; }
  // Frames stepped so far.
  uint64_t frames() const { return frames_; }

  const std::vector<Vec3>& positions() const { return x_; }
  std::vector<Vec3>& mutablePositions() { return x_; }
  const std::vector<Vec3>& velocities() const { return v_; }
  // Two triangles per grid cell, counter-clockwise seen from u x v.
  const std::vector<std::array<uint32_t, 3>>& triangles() const { return tris_; }
  struct Constraint {
    uint32_t a, b;
    double rest, compliance;
  };
  const std::vector<Constraint>& constraints() const { return constraints_; }
  int Index(int column, int row) const { return row * def_.columns + column; }
  // The implicit solver's last CG solve (zero for XPBD).
  SolveStats lastSolve() const { return implicit_ ? implicit_->lastSolve() : SolveStats{}; }
  // Largest relative stretch of a structural constraint, (len - rest) / rest.
  double MaxStretch() const;
  // The strain limiter's cycles in the last implicit substep (0: none ran);
  // implicitStrainIterations means it stopped at the bound, and a link may
  // still be past the limit (MaxStretch says by how much).
  int lastStrainCycles() const { return lastStrainCycles_; }

 private:
  explicit Cloth(const ClothDef& def);
  Status StepAny(double dt, const Vec3& gravity, const Vec3& wind, const WindField* field);
  Status StepImplicit(double dt, const Vec3& gravity, const Vec3& wind);
  // Strain limiting of the implicit state after a step of h seconds.
  void LimitStrain(std::vector<Vec3>& x, std::vector<Vec3>& v, double h);
  // The limiter's levels from the current inverse masses (pins).
  void BuildStrainLimiter();
  struct StrainLink {  // 40 bytes
    uint32_t a, b;
    double max2, target;    // (limit rest)^2, the length a stretched link goes back to
    double shareA, shareB;  // w_a / (w_a + w_b), w_b / (w_a + w_b)
  };
  // A coarse grid of the cloth: the particles of some columns and rows,
  // linked to their neighbours on it.
  struct StrainLevel {
    std::vector<StrainLink> links;
    // Each column's coarse column at or before it (its index in `columns`)
    // and its fraction of the way to the next; the same for rows.
    std::vector<int> columns, rows, columnBelow, rowBelow;
    std::vector<double> columnFraction, rowFraction;
  };
  // Coarsest first; the last is the cloth's own structural links.
  std::vector<StrainLevel> strainLevels_;
  bool strainBuilt_ = false;
  std::vector<Vec3> strainX0_, strainLevelX0_;
  int lastStrainCycles_ = 0;
  Status StepXpbd(double dt, const Vec3& gravity, const Vec3& wind);
  // Colliders and self-collision on the XPBD substep's positions.
  void ContactsXpbd(ThreadPool* pool);
  // proj_ for substeps of h seconds from the current inverse masses.
  void BuildProjections(double h);
  // The fault of the first particle whose position or velocity is not
  // finite (`when`: before or after the frame), or ok if there is none.
  Status FindNonFinite(const char* when);
  std::vector<xpbd::Tether> tethers_;  // xpbd::kTethers a particle
  std::vector<size_t> colorStart_;     // constraints_ sorted by colour
  std::unique_ptr<ThreadPool> ownPool_;
  ThreadPool* pool_ = nullptr;  // own or def.pool; null: serial
  // Wind and the external force field on positions x, velocities v, into f.
  void AddWind(ThreadPool* pool, const Vec3* x, const Vec3* v, const Vec3& wind, Vec3* f);
  const WindField* windField_ = nullptr;  // during a Step with a field
  ForceField externalForce_;
  std::vector<Collider> colliders_;
  std::vector<double> colliderThickness_;  // one per collider
  std::unique_ptr<clothcontact::SelfCollision> self_;
  std::vector<Vec3> selfX_, selfPrev_, selfDx_;
  size_t lastContacts_ = 0;
  class ExternalForce;          // gravity, damping and wind for the implicit solver
  std::vector<Vec3> triForce_;  // AddWind's per-triangle forces
  ClothDef def_;
  std::vector<Vec3> x_, v_, fext_;
  std::vector<xpbd::Point4> x4_, v4_, prev4_, fext4_;  // the XPBD substeps' state
  std::unique_ptr<System> implicit_;
  Vec3 gravity_, wind_;
  std::vector<double> w_;  // inverse masses
  std::vector<Constraint> constraints_;
  std::vector<xpbd::Projection> proj_;  // constraints_ as set for substeps of projH_ seconds
  double projH_ = 0;
  xpbd::Kernel kernel_ = kernels::Best();
  bool lastColourShared_ = false;  // the colouring ran out: its last colour may share particles
  std::vector<double> lambda_;
  std::vector<std::array<uint32_t, 3>> tris_;
  uint64_t frames_ = 0;
  std::optional<Diagnostic> fault_;
};

}  // namespace sylva::particles
