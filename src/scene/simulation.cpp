// The scene's simulation clock; see simulation.h. Sections:
//   wind and the scene-level forces (wind drag, attractor, vortex, noise)
//   emission (shapes, cones, births spread over a step, on-death bursts)
//   colliders (ground, terrain, plants and forests as triangle hierarchies)
//   cloth and flocks
//   drawing and the CSV dump
#include "scene/simulation.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <unordered_map>
#include <unordered_set>

#include "core/assert.h"
#include "core/rng.h"
#include "draw/convert.h"
#include "mesh/obj_reader.h"
#include "particles/cloth.h"
#include "particles/emitter.h"
#include "particles/flocking.h"
#include "particles/forces.h"
#include "particles/system.h"
#include "plant/surface_library.h"
#include "scene/plants.h"

namespace sylva::scene {
namespace {

using particles::ParticleState;

Diagnostic Warn(const SourceLoc& loc, std::string message) {
  Diagnostic d = MakeError(loc, std::move(message));
  d.severity = Severity::kWarning;
  return d;
}

Diagnostic Fail(const SourceLoc& loc, std::string message, ErrorKind kind = ErrorKind::kRuntime) {
  Diagnostic d = MakeError(loc, std::move(message));
  d.kind = kind;
  return d;
}

// --- wind and forces -------------------------------------------------------

// The scene's one wind: a mean velocity plus a divergence-free gust field.
struct Wind {
  Vec3 mean = Vec3::Zero();
  std::shared_ptr<particles::NoiseWind> gusts;  // null: no gusts
  Vec3 At(const Vec3& x, double t) const { return gusts ? gusts->Velocity(x, t) : mean; }
};

// The gust field sampled once a step on a grid over a system's particles
// (spacing a quarter of the eddy size, at most 48 nodes an axis) and
// interpolated trilinearly: a particle's wind then costs a few multiplies
// instead of sixteen cosines. Before Prepare, and off the grid, the exact
// field is used.
struct WindGrid {
  const Wind* wind = nullptr;
  bool valid = false;
  Vec3 origin = Vec3::Zero();
  double spacing = 1;
  int nx = 0, ny = 0, nz = 0;
  std::vector<Vec3> samples;

  void Prepare(const ParticleState& s, double t, double eddy) {
    valid = false;
    if (!wind || !wind->gusts || s.size() == 0) return;
    Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
    for (size_t i = 0; i < s.size(); ++i) {
      if (s.invMass[i] == 0) continue;
      lo = lo.cwiseMin(s.position[i]);
      hi = hi.cwiseMax(s.position[i]);
    }
    PrepareBox(lo, hi, t, eddy);
  }

  // Over points x (a cloth's vertices).
  void Prepare(const std::vector<Vec3>& x, double t, double eddy) {
    valid = false;
    if (!wind || !wind->gusts || x.empty()) return;
    Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
    for (const Vec3& p : x) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    PrepareBox(lo, hi, t, eddy);
  }

  void PrepareBox(Vec3 lo, Vec3 hi, double t, double eddy) {
    if (!lo.allFinite() || !hi.allFinite() || !(lo.array() <= hi.array()).all()) return;
    spacing = eddy / 4;
    lo.array() -= 2 * spacing;  // room for a step's motion
    hi.array() += 2 * spacing;
    const Vec3 extent = hi - lo;
    if (!extent.allFinite()) return;  // beyond double's range: sampled exactly
    if (extent.maxCoeff() / spacing > 47) spacing = extent.maxCoeff() / 47;
    nx = int(std::ceil(extent.x() / spacing)) + 1;
    ny = int(std::ceil(extent.y() / spacing)) + 1;
    nz = int(std::ceil(extent.z() / spacing)) + 1;
    origin = lo;
    samples.resize(size_t(nx) * size_t(ny) * size_t(nz));
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
          samples[(size_t(k) * size_t(ny) + size_t(j)) * size_t(nx) + size_t(i)] =
              wind->At(origin + spacing * Vec3(i, j, k), t);
    valid = true;
  }

  Vec3 At(const Vec3& x, double t) const {
    if (!valid) return wind->At(x, t);
    const Vec3 g = (x - origin) / spacing;
    if (!g.allFinite()) return wind->At(x, t);
    const double gx = std::floor(g.x()), gy = std::floor(g.y()), gz = std::floor(g.z());
    if (!(gx >= 0 && gy >= 0 && gz >= 0 && gx + 1 < nx && gy + 1 < ny && gz + 1 < nz))
      return wind->At(x, t);
    const int i = int(gx), j = int(gy), k = int(gz);
    const double fx = g.x() - gx, fy = g.y() - gy, fz = g.z() - gz;
    auto at = [&](int di, int dj, int dk) -> const Vec3& {
      return samples[(size_t(k + dk) * size_t(ny) + size_t(j + dj)) * size_t(nx) + size_t(i + di)];
    };
    const Vec3 x00 = at(0, 0, 0) + fx * (at(1, 0, 0) - at(0, 0, 0));
    const Vec3 x10 = at(0, 1, 0) + fx * (at(1, 1, 0) - at(0, 1, 0));
    const Vec3 x01 = at(0, 0, 1) + fx * (at(1, 0, 1) - at(0, 0, 1));
    const Vec3 x11 = at(0, 1, 1) + fx * (at(1, 1, 1) - at(0, 1, 1));
    const Vec3 y0 = x00 + fy * (x10 - x00), y1 = x01 + fy * (x11 - x01);
    return y0 + fz * (y1 - y0);
  }
};

// Drag relative to the wind: f = -(k1 + k2 |u|) u with u = v - wind(x, t).
// Immovable particles (stuck where they landed) feel no force, so the wind,
// the dearest part of a step, is not sampled for them.
class WindDrag : public particles::LocalForce {
 public:
  WindDrag(double linear, double quadratic, const WindGrid* wind)
      : k1_(linear), k2_(quadratic), wind_(wind) {}
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override {
    for (size_t i = begin; i < end; ++i) {
      if (s.invMass[i] == 0) continue;
      const Vec3 u = wind_ ? Vec3(v[i] - wind_->At(x[i], s.time)) : v[i];
      f[i - begin] -= (k1_ + k2_ * u.norm()) * u;
    }
  }

 private:
  double k1_, k2_;
  const WindGrid* wind_;
};

// An acceleration field a(x, t), applied as m a.
class AccelerationField : public particles::LocalForce {
 public:
  using Fn = std::function<Vec3(const Vec3& x, double t)>;
  explicit AccelerationField(Fn fn) : fn_(std::move(fn)) {}
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3*, Vec3* f, size_t begin,
                       size_t end) const override {
    for (size_t i = begin; i < end; ++i)
      if (s.invMass[i] > 0) f[i - begin] += s.mass[i] * fn_(x[i], s.time);
  }

 private:
  Fn fn_;
};

// Falling leaves: a thin plate whose orientation is integrated with the
// particle. The air pushes on the plate along its normal n only (a plate
// slides easily edgewise), so a tilted leaf glides sideways; the flow turns
// the plate broadside to it (torque a (n.u)(n x u) |u|^2 about the centre
// of pressure, damped), so the tilt swings back and forth: the leaf
// flutters and zigzags as it falls instead of dropping straight.
struct LeafState {
  Vec3 n = Vec3::UnitZ();  // plate normal (the leaf mesh's +Z)
  Vec3 w = Vec3::Zero();   // angular velocity, rad/s
};
using LeafStates = std::unordered_map<uint32_t, LeafState>;

// Extra drag along the plate's normal: f = -k (u.n) n, u = v - wind.
class PlateDrag : public particles::LocalForce {
 public:
  PlateDrag(double k, const Wind* wind, const LeafStates* leaves)
      : k_(k), wind_(wind), leaves_(leaves) {}
  void AccumulateRange(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f, size_t begin,
                       size_t end) const override {
    for (size_t i = begin; i < end; ++i) {
      const auto it = leaves_->find(s.id[i]);
      if (it == leaves_->end() || s.invMass[i] == 0) continue;
      const Vec3 u = wind_ ? Vec3(v[i] - wind_->At(x[i], s.time)) : v[i];
      const Vec3& n = it->second.n;
      f[i - begin] -= k_ * u.dot(n) * n;
    }
  }

 private:
  double k_;
  const Wind* wind_;
  const LeafStates* leaves_;
};

// --- emission ----------------------------------------------------------------

using particles::InCone;

// One <emitter>: the particles library's Emitter made from it, with its
// shape, cone, lifetimes and the system's `max` (simulation.h).
struct Source {
  const EmitterDef* def = nullptr;
  std::optional<particles::Emitter> emitter;
};

// The library's definition of a scene emitter. Terrains and plants are
// placements of the scene's own (uniform over the terrain's x-z extent, on
// its surface; a plant's tips or leaves, or its segments by length).
Expected<particles::Emitter> MakeEmitter(const EmitterDef& e, uint64_t seed, uint64_t max,
                                         const terrain::HeightField* terrain,
                                         const PlantPoints* points) {
  particles::EmitterDef d;
  d.rate = e.rate;
  d.position = e.at;
  d.size = e.size;
  switch (e.shape) {
    case EmitterShape::kPoint:
      d.shape = particles::EmitterShape::kPoint;
      break;
    case EmitterShape::kSphere:
      d.shape = particles::EmitterShape::kSphere;
      break;
    case EmitterShape::kBox:
      d.shape = particles::EmitterShape::kBox;
      break;
    case EmitterShape::kDisc:
      d.shape = particles::EmitterShape::kDisc;
      break;
    case EmitterShape::kTerrain: {
      d.shape = particles::EmitterShape::kFunction;
      d.place = [terrain](const Vec3& u) {
        const terrain::HeightField& t = *terrain;
        const double hx = t.def().sizeX / 2, hz = t.def().sizeZ / 2;
        const double px = -hx + 2 * hx * u.x(), pz = -hz + 2 * hz * u.y();
        return Vec3(Vec3(px, t.Height(px, pz), pz) + 0.01 * t.Normal(px, pz));
      };
      break;
    }
    case EmitterShape::kPlant: {
      d.shape = particles::EmitterShape::kFunction;
      if (e.part == PlantPart::kSegments) {
        auto cumulative = std::make_shared<std::vector<double>>();
        double sum = 0;
        for (double len : points->segmentLengths) cumulative->push_back(sum += len);
        d.place = [points, cumulative](const Vec3& u) {
          const double pick = u.x() * cumulative->back();
          const size_t i = size_t(std::lower_bound(cumulative->begin(), cumulative->end(), pick) -
                                  cumulative->begin());
          return points->segmentPoints[std::min(i, points->segmentPoints.size() - 1)];
        };
      } else {
        const std::vector<Vec3>* from =
            e.part == PlantPart::kTips ? &points->tips : &points->leaves;
        d.place = [from](const Vec3& u) {
          return (*from)[std::min(from->size() - 1, size_t(u.x() * double(from->size())))];
        };
      }
      break;
    }
  }
  d.velocity = e.speed * e.direction.normalized();
  d.spreadDegrees = e.spreadDegrees;
  d.lifetime = (e.lifetime.x() + e.lifetime.y()) / 2;
  d.lifetimeJitter = (e.lifetime.y() - e.lifetime.x()) / 2;
  d.mass = e.mass;
  d.radiusStart = d.radiusEnd = float(e.radius);
  d.maxAlive = max;
  d.seed = seed;
  auto made = particles::Emitter::Create(d);
  if (!made) {
    Diagnostic diag = made.error();
    diag.loc = e.loc;
    diag.kind = ErrorKind::kInput;
    diag.message = "<emitter>: " + diag.message;
    return diag;
  }
  return made;
}

// --- the systems -------------------------------------------------------------

struct MeshSource {
  std::shared_ptr<const mesh::TriangleMesh> mesh;
};

struct ParticleSystem {
  const ParticlesDef* def = nullptr;
  std::unique_ptr<particles::System> system;
  particles::Integrator integrator = particles::Integrator::kSymplecticEuler;
  bool adaptive = false;
  std::vector<Source> sources;
  struct Death {
    ParticleSystem* target;
    const OnDeathDef* def;
  };
  std::vector<Death> onDeath;
  uint64_t dropped = 0;  // births refused at `max`
  bool warned = false;   // a step's warning is in Impl::warnings (the first only)
  std::unique_ptr<WindGrid> windGrid = std::make_unique<WindGrid>();
  std::shared_ptr<const mesh::TriangleMesh> drawMesh;  // as="mesh"
  // Leaves (draw as="mesh" with spin): orientation by particle id.
  bool flutter = false;
  std::unique_ptr<LeafStates> leaves;
  double plateK = 0;  // drag along the normal, N s/m
  uint64_t leafSeed = 0;
  // Colliders that are cloth: rebuilt from the sheet before every step.
  struct ClothCollider {
    size_t cloth;     // index into Impl::cloths
    size_t collider;  // index into the system's colliders
    const CollideDef* def;
  };
  std::vector<ClothCollider> clothColliders;
  // Particles stuck to a cloth (a <collide stick="true"> naming it): each
  // rides on the triangle it touched, at its barycentric coordinates and
  // its height along the triangle's normal, moved with the sheet after the
  // sheet steps (the particle system keeps it pinned).
  struct Rider {
    uint32_t id;
    size_t cloth;
    uint32_t triangle;
    double b1, b2;  // barycentric coordinates of corners 1 and 2
    double height;  // along the unit normal, m
  };
  std::vector<Rider> riders;
  std::unordered_set<uint32_t> pinnedSeen;  // immovable particles already looked at
  // <springs>: the library's Springs, which System::RemoveDead renumbers
  // (a spring follows its particles; one with a dead end goes).
  const SpringsDef* springsDef = nullptr;
  std::shared_ptr<particles::Springs> springs;
  std::optional<uint32_t> lastBorn;  // chain: the id of the latest birth
  // Joins particle i, just born, as `between` says.
  Status Join(size_t i);
  // Turns each leaf by the flow's torque and its spin; new ones get a
  // random orientation and spin, dead ones are forgotten.
  void TurnLeaves(double h, const Wind* wind, double time);
};

Status ParticleSystem::Join(size_t i) {
  const ParticleState& st = system->state;
  const SpringsDef& d = *springsDef;
  auto join = [&](size_t j) -> Status {
    const double rest = d.rest.value_or((st.position[i] - st.position[j]).norm());
    return springs->Add(uint32_t(j), uint32_t(i), rest, d.k, d.damping);
  };
  if (d.between == SpringTopology::kChain) {
    // The latest birth is the last particle before i, if it still lives
    // (births are appended; RemoveDead keeps the order).
    const bool chained = lastBorn && i > 0 && st.id[i - 1] == *lastBorn;
    lastBorn = st.id[i];
    return chained ? join(i - 1) : Status{};
  }
  // Nearest (and for `grid` every particle within 1.5 times the nearest
  // distance, at most 6): a linear scan, bounded by `max` (Create).
  double best = HUGE_VAL;
  size_t nearest = i;
  for (size_t j = 0; j < i; ++j) {
    const double d2 = (st.position[j] - st.position[i]).squaredNorm();
    if (d2 < best) best = d2, nearest = j;
  }
  if (nearest == i) return {};
  if (d.between == SpringTopology::kNearest) return join(nearest);
  const double reach = 2.25 * best;  // (1.5 x)^2
  int joined = 0;
  for (size_t j = 0; j < i && joined < 6; ++j) {
    if ((st.position[j] - st.position[i]).squaredNorm() > reach) continue;
    if (Status s = join(j); !s.ok()) return s;
    ++joined;
  }
  return {};
}

void ParticleSystem::TurnLeaves(double h, const Wind* wind, double time) {
  const ParticleState& st = system->state;
  const double spin = def->draw.spinDegrees * kDegToRad;
  LeafStates next;
  next.reserve(st.size());
  for (size_t i = 0; i < st.size(); ++i) {
    auto it = leaves->find(st.id[i]);
    LeafState leaf;
    if (it == leaves->end()) {
      const uint64_t k = CounterHash(leafSeed, st.id[i]);
      leaf.n = InCone(Vec3::UnitY(), 180, ToUnit(k), ToUnit(Mix64(k)));
      leaf.w = spin * InCone(Vec3::UnitY(), 180, ToUnit(Mix64(k ^ 1)), ToUnit(Mix64(k ^ 2)));
    } else {
      leaf = it->second;
    }
    if (st.invMass[i] > 0) {
      const Vec3 u = wind ? Vec3(st.velocity[i] - wind->At(st.position[i], time)) : st.velocity[i];
      const double speed = u.norm();
      Vec3 torque = Vec3::Zero();
      if (speed > 1e-9) {
        const Vec3 d = u / speed;
        torque = 20.0 * leaf.n.dot(d) * leaf.n.cross(d) * speed * speed;
      }
      leaf.w += h * (torque - 1.5 * leaf.w);
      const double angle = leaf.w.norm() * h;
      if (angle > 0) leaf.n = Eigen::AngleAxisd(angle, leaf.w.normalized()) * leaf.n;
      leaf.n.normalize();
    }
    next.emplace(st.id[i], leaf);
  }
  *leaves = std::move(next);
}

struct ClothSheet {
  const ClothDef* def = nullptr;
  std::unique_ptr<particles::Cloth> cloth;
  // Other cloths it collides with: (index into Impl::cloths, its collider
  // index, the <collide>), rebuilt from the other sheet before each step.
  struct Other {
    size_t cloth, collider;
    const CollideDef* def;
  };
  std::vector<Other> others;
  std::unique_ptr<WindGrid> windGrid = std::make_unique<WindGrid>();  // the gusts over it
  Vec3 gravity = Vec3::Zero();
  // Its triangles as a collider's hierarchy where the sheet is now: built on
  // first use, shared by every particle system, substep and other sheet
  // that collides with it, dropped when the sheet steps.
  std::shared_ptr<const particles::TriangleBvh> bvh;
  const std::shared_ptr<const particles::TriangleBvh>& Bvh() {
    if (!bvh)
      bvh = std::make_shared<const particles::TriangleBvh>(cloth->positions(), cloth->triangles());
    return bvh;
  }
};

struct Flock {
  const FlockDef* def = nullptr;
  std::unique_ptr<WindGrid> windGrid = std::make_unique<WindGrid>();
  std::unique_ptr<particles::System> system;
  std::shared_ptr<const mesh::TriangleMesh> drawMesh;
};

// A dart: the boids' default mesh, 1 unit long along +Z.
std::shared_ptr<mesh::TriangleMesh> DartMesh() {
  auto m = std::make_shared<mesh::TriangleMesh>();
  const mesh::Vec3f p[] = {
      {0, 0, 0.5f}, {-0.45f, 0, -0.5f}, {0, 0.08f, -0.3f}, {0.45f, 0, -0.5f}, {0, -0.12f, -0.4f}};
  const uint32_t tris[][3] = {{0, 1, 2}, {0, 2, 3}, {0, 4, 1}, {0, 3, 4}};
  for (const auto& t : tris) {
    const mesh::Vec3f n = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]).normalized();
    for (uint32_t k : t) {
      m->positions.push_back(p[k]);
      m->normals.push_back(n);
      m->uvs.push_back({0, 0});
      m->indices.push_back(uint32_t(m->indices.size()));
    }
    m->material.push_back(0);
  }
  return m;
}

}  // namespace

// An attractor's centre at another element (`of`): fixed for a plant,
// forest or emitter; the centroid of a flock or cloth at each step.
struct Centre {
  std::shared_ptr<Vec3> at;  // read by the attractor's force
  std::string of;
  SourceLoc loc;
  std::function<Vec3()> follow;  // set for what moves
};

struct Simulation::Impl {
  const Scene* scene = nullptr;
  const BuiltScene* built = nullptr;
  double h = 1.0 / 120;
  double time = 0;
  uint64_t steps = 0;
  DiagnosticList warnings;  // of steps taken (Simulation::warnings)
  Wind wind;
  bool hasWind = false;
  std::vector<std::unique_ptr<ParticleSystem>> systems;
  std::vector<ClothSheet> cloths;
  std::vector<Flock> flocks;
  std::vector<Centre> centres;
  Status PlaceCentres();
  std::map<std::string, std::shared_ptr<const particles::TriangleBvh>> bvhs, leafBvhs;
  std::map<std::string, std::shared_ptr<const particles::CapsuleBvh>> capsuleBvhs;
  std::shared_ptr<const particles::CapsuleBvh> CapsulesOf(const std::string& id) {
    auto& slot = capsuleBvhs[id];
    if (!slot) slot = std::make_shared<const particles::CapsuleBvh>(built->points.at(id).capsules);
    return slot;
  }
  std::shared_ptr<const particles::TriangleBvh> LeavesOf(const std::string& id) {
    auto& slot = leafBvhs[id];
    if (slot) return slot;
    std::vector<Vec3> v;
    std::vector<std::array<uint32_t, 3>> t;
    for (const auto& tri : built->points.at(id).leafTriangles) {
      const uint32_t base = uint32_t(v.size());
      v.insert(v.end(), tri.begin(), tri.end());
      t.push_back({base, base + 1, base + 2});
    }
    slot = std::make_shared<const particles::TriangleBvh>(std::move(v), std::move(t));
    return slot;
  }

  // The colliders of `collides`, validated; a cloth named in `with` is
  // skipped silently when it is `selfId` (the cloth's own self-collision)
  // and with a warning otherwise.
  Status CollidersOf(const std::vector<CollideDef>& collides, const std::string& selfId,
                     DiagnosticList& diags, std::vector<particles::Collider>& out);
  Status AddColliders(particles::System& system, const std::vector<CollideDef>& collides,
                      DiagnosticList& diags);
  // The cloths a particle system collides with: a triangle collider each,
  // added to the system now and rebuilt from the sheet before every step.
  Status AddClothColliders(ParticleSystem& ps);
  Status RefreshClothColliders(ParticleSystem& ps);
  // Particles of `ps` stuck to a cloth since the last call become riders.
  void CatchRiders(ParticleSystem& ps);
  // Riders follow their triangles, after the cloths stepped h seconds.
  void MoveRiders();
  std::shared_ptr<const particles::TriangleBvh> BvhOf(const std::string& id);
  Status Emit(ParticleSystem& ps, double h);
  Status Step();
};

std::shared_ptr<const particles::TriangleBvh> Simulation::Impl::BvhOf(const std::string& id) {
  const auto cached = bvhs.find(id);
  if (cached != bvhs.end()) return cached->second;
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  const auto it = built->meshesOf.find(id);
  if (it != built->meshesOf.end()) {
    for (size_t k : it->second) {
      const BuiltMesh& m = built->meshes[k];
      for (const draw::Instance& inst : m.instances) {
        const Eigen::Matrix4d t = inst.transform.cast<double>();
        const uint32_t base = uint32_t(vertices.size());
        for (const mesh::Vec3f& p : m.mesh->positions)
          vertices.push_back((t * p.cast<double>().homogeneous()).head<3>());
        for (size_t i = 0; i + 2 < m.mesh->indices.size(); i += 3)
          triangles.push_back({base + m.mesh->indices[i], base + m.mesh->indices[i + 1],
                               base + m.mesh->indices[i + 2]});
      }
    }
  }
  auto bvh =
      std::make_shared<const particles::TriangleBvh>(std::move(vertices), std::move(triangles));
  bvhs[id] = bvh;
  return bvh;
}

Status Simulation::Impl::CollidersOf(const std::vector<CollideDef>& collides,
                                     const std::string& selfId, DiagnosticList& diags,
                                     std::vector<particles::Collider>& out) {
  for (const CollideDef& c : collides) {
    const particles::Response response =
        c.stick ? particles::Response::kStick : particles::Response::kBounce;
    for (const std::string& id : c.with) {
      std::vector<particles::Collider> parts;
      if (id == "ground") {
        parts.push_back(particles::Collider::Plane(Vec3::Zero(), Vec3::UnitY()));
      } else {
        bool isCloth = false;
        for (const ClothDef& cl : scene->cloths) isCloth = isCloth || cl.id == id;
        if (isCloth) {
          // A cloth with itself: its self-collision (the caller). With
          // another cloth or particles: once the cloths exist (the end of
          // Create).
          continue;
        }
        const auto pts = built->points.find(id);
        if (pts != built->points.end()) {
          // A plant or forest: capsules for the branches, triangles for the
          // leaves.
          parts.push_back(particles::Collider::Capsules(CapsulesOf(id)));
          if (!pts->second.leafTriangles.empty())
            parts.push_back(particles::Collider::Mesh(LeavesOf(id)));
        } else {
          parts.push_back(particles::Collider::Mesh(BvhOf(id)));
        }
      }
      for (particles::Collider& part : parts) {
        part.Restitution(c.restitution).Friction(std::min(c.friction, 1e3)).Respond(response);
        if (Status s = particles::Validate(part); !s.ok()) {
          Diagnostic d = s.error();
          d.loc = c.loc;
          return d;
        }
        out.push_back(std::move(part));
      }
    }
  }
  return {};
}

Status Simulation::Impl::AddColliders(particles::System& system,
                                      const std::vector<CollideDef>& collides,
                                      DiagnosticList& diags) {
  std::vector<particles::Collider> colliders;
  if (Status s = CollidersOf(collides, "", diags, colliders); !s.ok()) return s;
  for (particles::Collider& c : colliders) {
    const Status s = system.AddCollider(std::move(c));
    SYLVA_ASSERT(s.ok());  // validated above
  }
  return {};
}

// A cloth where it is now, as the triangle collider `def` describes.
static particles::Collider ClothAsCollider(ClothSheet& sheet, const CollideDef& def) {
  particles::Collider c = particles::Collider::Mesh(sheet.Bvh());
  c.Restitution(def.restitution)
      .Friction(std::min(def.friction, 1e3))
      .Respond(def.stick ? particles::Response::kStick : particles::Response::kBounce);
  return c;
}

Status Simulation::Impl::RefreshClothColliders(ParticleSystem& ps) {
  for (const ParticleSystem::ClothCollider& cc : ps.clothColliders) {
    particles::Collider c = ClothAsCollider(cloths[cc.cloth], *cc.def);
    if (Status s = ps.system->SetCollider(cc.collider, std::move(c)); !s.ok()) {
      Diagnostic d = s.error();
      d.loc = cc.def->loc;
      return d;
    }
  }
  return {};
}

Status Simulation::Impl::AddClothColliders(ParticleSystem& ps) {
  for (const CollideDef& c : ps.def->collides) {
    for (const std::string& id : c.with) {
      for (size_t k = 0; k < cloths.size(); ++k) {
        if (cloths[k].def->id != id) continue;
        ps.clothColliders.push_back({k, ps.system->colliders().size(), &c});
        // A placeholder (the ground plane far below) until the refresh.
        if (Status s = ps.system->AddCollider(
                particles::Collider::Plane(Vec3(0, -1e12, 0), Vec3::UnitY()));
            !s.ok())
          return s;
      }
    }
  }
  return RefreshClothColliders(ps);
}

Status Simulation::Impl::Emit(ParticleSystem& ps, double step) {
  ParticleState& st = ps.system->state;
  const std::vector<particles::Collider>& colliders = ps.system->colliders();
  for (Source& src : ps.sources) {
    // Births spread over the step, moved on for their age unless that move
    // would cross a collider (then born at the emitter: the step meets the
    // collider); the first step adds the burst.
    const size_t first = st.size();
    if (Status s = src.emitter->Emit(st, step, colliders); !s.ok()) {
      Diagnostic d = s.error();
      d.loc = src.def->loc;
      return d;
    }
    if (steps == 0) src.emitter->Burst(st, src.def->burst);
    if (ps.springs) {
      for (size_t i = first; i < st.size(); ++i) {
        if (Status s = ps.Join(i); !s.ok()) {
          Diagnostic d = s.error();
          d.loc = ps.springsDef->loc;
          return d;
        }
      }
    }
  }
  return {};
}

Status Simulation::Impl::PlaceCentres() {
  auto mean = [](const std::vector<Vec3>& points) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : points) c += p;
    return points.empty() ? c : Vec3(c / double(points.size()));
  };
  for (Centre& c : centres) {
    const auto points = built->points.find(c.of);
    if (points != built->points.end()) {  // a plant or forest
      *c.at = mean(points->second.segmentPoints);
      continue;
    }
    bool found = false;
    for (size_t k = 0; k < cloths.size() && !found; ++k) {
      if (cloths[k].def->id != c.of) continue;
      const particles::Cloth* cloth = cloths[k].cloth.get();
      c.follow = [cloth, mean] { return mean(cloth->positions()); };
      found = true;
    }
    for (size_t k = 0; k < flocks.size() && !found; ++k) {
      if (flocks[k].def->id != c.of) continue;
      const ParticleState* boids = &flocks[k].system->state;
      c.follow = [boids, mean] { return mean(boids->position); };
      found = true;
    }
    for (const ParticlesDef& p : scene->particles) {
      for (const EmitterDef& e : p.emitters) {
        if (found || e.id != c.of) continue;
        found = true;
        const auto target = built->points.find(e.of);  // an emitter on a plant's parts
        *c.at = target != built->points.end() ? mean(target->second.segmentPoints) : e.at;
      }
    }
    if (!found)  // the reader checks the kind of every `of`: this is a bug
      return Fail(c.loc, "'of=\"" + c.of + "\"' names nothing an attractor can follow");
    if (c.follow) *c.at = c.follow();
  }
  return {};
}

// The point of triangle (a, b, c) nearest p, as barycentric coordinates
// of b and c (Ericson, "Real-Time Collision Detection", 5.1.5).
static std::pair<double, double> NearestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                                   const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {0, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {d1 / (d1 - d3), 0};
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {0, d2 / (d2 - d6)};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {1 - w, w};
  }
  const double denom = 1 / (va + vb + vc);
  return {vb * denom, vc * denom};
}

void Simulation::Impl::CatchRiders(ParticleSystem& ps) {
  bool sticky = false;
  for (const ParticleSystem::ClothCollider& cc : ps.clothColliders) sticky |= cc.def->stick;
  if (!sticky) return;
  const ParticleState& st = ps.system->state;
  for (size_t i = 0; i < st.size(); ++i) {
    if (st.invMass[i] != 0 || !ps.pinnedSeen.insert(st.id[i]).second) continue;
    // The nearest triangle of a sticky cloth, where the sheets are now (the
    // colliders' positions: the cloths step after the particles).
    const Vec3 x = st.position[i];
    double best = HUGE_VAL;
    ParticleSystem::Rider rider{};
    for (const ParticleSystem::ClothCollider& cc : ps.clothColliders) {
      if (!cc.def->stick) continue;
      const particles::Cloth& cloth = *cloths[cc.cloth].cloth;
      const std::vector<Vec3>& v = cloth.positions();
      const auto& tris = cloth.triangles();
      for (size_t k = 0; k < tris.size(); ++k) {
        const Vec3 &a = v[tris[k][0]], &b = v[tris[k][1]], &c = v[tris[k][2]];
        // A corner farther than the triangle's longest edge and the best so
        // far: no point of the triangle is nearer.
        const double reach =
            std::sqrt(std::max({(b - a).squaredNorm(), (c - a).squaredNorm()})) + best;
        if ((x - a).squaredNorm() > reach * reach) continue;
        const auto [b1, b2] = NearestOnTriangle(x, a, b, c);
        const Vec3 q = a + b1 * (b - a) + b2 * (c - a);
        const double d = (x - q).norm();
        if (d >= best) continue;
        const Vec3 n = (b - a).cross(c - a);
        const double area2 = n.norm();
        if (!(area2 > 0)) continue;
        best = d;
        rider = {st.id[i], cc.cloth, uint32_t(k), b1, b2, (x - q).dot(n / area2)};
      }
    }
    // Stuck where a sticky cloth's collider stopped it: its centre at its
    // radius from the sheet (anything farther stuck to something else).
    if (best <= double(st.radius[i]) + 1e-6) ps.riders.push_back(rider);
  }
}

void Simulation::Impl::MoveRiders() {
  for (auto& ps : systems) {
    if (ps->riders.empty()) continue;
    ParticleState& st = ps->system->state;
    size_t kept = 0;
    for (const ParticleSystem::Rider& r : ps->riders) {
      // Ids grow with births and RemoveDead keeps the order: a search.
      const auto it = std::lower_bound(st.id.begin(), st.id.end(), r.id);
      if (it == st.id.end() || *it != r.id) continue;  // died
      const size_t i = size_t(it - st.id.begin());
      const particles::Cloth& cloth = *cloths[r.cloth].cloth;
      const auto& t = cloth.triangles()[r.triangle];
      const Vec3 &a = cloth.positions()[t[0]], &b = cloth.positions()[t[1]],
                 &c = cloth.positions()[t[2]];
      const Vec3 n = (b - a).cross(c - a);
      const double area2 = n.norm();
      Vec3 x = a + r.b1 * (b - a) + r.b2 * (c - a);
      if (area2 > 0) x += (r.height / area2) * n;
      st.velocity[i] = (x - st.position[i]) / h;
      st.position[i] = x;
      ps->riders[kept++] = r;
    }
    ps->riders.resize(kept);
  }
}

Status Simulation::Impl::Step() {
  for (Centre& c : centres)
    if (c.follow) *c.at = c.follow();
  for (auto& ps : systems) {
    const int sub = ps->def->substeps;
    for (int k = 0; k < sub; ++k) {
      const double hs = h / sub;
      if (Status s = RefreshClothColliders(*ps); !s.ok()) return s;
      if (Status s = Emit(*ps, hs); !s.ok()) return s;
      if (ps->flutter) ps->TurnLeaves(hs, hasWind ? &wind : nullptr, time);
      if (hasWind && scene->wind)
        ps->windGrid->Prepare(ps->system->state, ps->system->time, scene->wind->scale);
      Status s = ps->adaptive ? ps->system->StepAdaptive(hs, particles::AdaptiveOptions{})
                              : ps->system->Step(hs, ps->integrator);
      if (!s.ok()) {
        Diagnostic d = s.error();
        d.loc = ps->def->loc;
        d.message = "<particles> at t = " + std::to_string(time) + " s: " + d.message;
        // A warning: the step was taken (particle collisions that did not
        // converge); the first of each system is kept, and the run goes on.
        if (d.severity != Severity::kWarning) return d;
        if (!ps->warned) warnings.Add(std::move(d));
        ps->warned = true;
      }
      CatchRiders(*ps);
    }
    // Deaths: secondary bursts where they happen, then removal.
    ParticleState& st = ps->system->state;
    for (const ParticleSystem::Death& death : ps->onDeath) {
      ParticleState& target = death.target->system->state;
      for (size_t i = 0; i < st.size(); ++i) {
        if (st.age[i] < st.lifetime[i]) continue;
        for (int c = 0; c < death.def->count; ++c) {
          if (target.size() >= death.target->def->max) {
            death.target->dropped += uint64_t(death.def->count - c);  // full: no loop over them
            break;
          }
          Vec3 v = Vec3::Zero();
          double mass = 1, lifetime = 1;
          float radius = 0;
          if (!death.target->sources.empty()) {
            particles::Emitter& e = *death.target->sources[0].emitter;
            const particles::Birth drawn = e.Next();
            v = drawn.velocity;
            lifetime = drawn.lifetime;
            mass = e.def().mass;
            radius = e.def().radiusStart;
          }
          target.Add(st.position[i], st.velocity[i] + v, mass, lifetime);
          target.radius.back() = radius;
        }
      }
    }
    ps->system->RemoveDead();  // springs follow their particles
  }
  for (ClothSheet& c : cloths) {
    for (const ClothSheet::Other& o : c.others) {
      particles::Collider other = ClothAsCollider(cloths[o.cloth], *o.def);
      if (Status s = c.cloth->SetCollider(o.collider, std::move(other)); !s.ok()) {
        Diagnostic d = s.error();
        d.loc = o.def->loc;
        return d;
      }
    }
    // The wind at each triangle (gusts smaller than the sheet bend it),
    // from the gusts sampled on a grid over the sheet.
    const double t = time;
    const bool gusts = hasWind && c.def->wind && wind.gusts;
    if (gusts) c.windGrid->Prepare(c.cloth->positions(), t, scene->wind->scale);
    const WindGrid* air = c.windGrid.get();
    Status s = gusts
                   ? c.cloth->StepInWindField(h, c.gravity,
                                              [air, t](const Vec3& x) { return air->At(x, t); })
                   : c.cloth->Step(h, c.gravity, hasWind && c.def->wind ? wind.mean : Vec3::Zero());
    c.bvh.reset();  // the sheet moved
    if (!s.ok()) {
      Diagnostic d = s.error();
      d.loc = c.def->loc;
      d.message = "<cloth> at t = " + std::to_string(time) + " s: " + d.message;
      return d;
    }
  }
  MoveRiders();
  for (Flock& f : flocks) {
    if (Status s = f.system->Step(h, particles::Integrator::kSymplecticEuler); !s.ok()) {
      Diagnostic d = s.error();
      d.loc = f.def->loc;
      return d;
    }
  }
  time += h;
  ++steps;
  return {};
}

Simulation::Simulation() : impl_(std::make_unique<Impl>()) {}
Simulation::~Simulation() = default;

double Simulation::time() const {
  return impl_->time;
}
double Simulation::stepLength() const {
  return impl_->h;
}
const DiagnosticList& Simulation::warnings() const {
  return impl_->warnings;
}

Status Simulation::AdvanceTo(double t) {
  // A bound a user can see: past it the run would take hours, not finish.
  const double steps = (t - impl_->time) / impl_->h;
  if (steps > kMaxStepsPerAdvance) {
    Diagnostic d = MakeError(
        impl_->scene->simulation.loc,
        "reaching t = " + std::to_string(t) + " s would take " + std::to_string(uint64_t(steps)) +
            " steps of 1/(fps x substeps) "
            "s, more than the limit of " +
            std::to_string(uint64_t(kMaxStepsPerAdvance)) + "; lower the time, fps or substeps");
    d.kind = ErrorKind::kInput;
    return d;
  }
  while (impl_->time + impl_->h / 2 < t)
    if (Status s = impl_->Step(); !s.ok()) return s;
  return {};
}

Expected<std::unique_ptr<Simulation>> Simulation::Create(const Scene& scene,
                                                         const BuiltScene& built,
                                                         const SimulationOptions& options,
                                                         DiagnosticList& diags) {
  std::unique_ptr<Simulation> sim(new Simulation());
  Impl& m = *sim->impl_;
  m.scene = &scene;
  m.built = &built;
  m.h = 1.0 / (scene.simulation.fps * scene.simulation.substeps);
  const int threads = scene.simulation.threads ? scene.simulation.threads : options.threads;

  if (scene.wind) {
    m.hasWind = true;
    m.wind.mean = scene.wind->velocity;
    if (scene.wind->gust > 0) {
      particles::NoiseWindDef w;
      w.mean = scene.wind->velocity;
      w.speed = scene.wind->gust;
      w.scale = scene.wind->scale;
      w.frequency = 2 * kPi * scene.wind->frequency;
      w.seed = ElementSeed(scene.seed, "", "wind", 0);
      auto gusts = particles::NoiseWind::Create(w);
      if (!gusts) return Fail(scene.wind->loc, gusts.error().message, ErrorKind::kInput);
      m.wind.gusts = *gusts;
    }
  }
  const Wind* wind = m.hasWind ? &m.wind : nullptr;
  plant::SurfaceLibrary surfaces(scene.path);

  // Loads a draw mesh: `~name` from the surface library's folders, or .obj.
  auto loadMesh = [&](const DrawDef& d) -> Expected<std::shared_ptr<const mesh::TriangleMesh>> {
    std::string path = d.mesh;
    if (!path.empty() && path[0] == '~') {
      path.clear();
      for (const std::string& dir : surfaces.searchPath()) {
        const std::string candidate = dir + "/" + d.mesh.substr(1) + ".obj";
        struct stat st {};
        if (stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
          path = candidate;
          break;
        }
      }
      if (path.empty())
        return Fail(d.loc, "no surface file " + d.mesh.substr(1) + ".obj for '" + d.mesh + "'",
                    ErrorKind::kInput);
    }
    Expected<mesh::TriangleMesh> obj = mesh::ReadObj(path);
    if (!obj) return Fail(d.loc, obj.error().message, ErrorKind::kInput);
    return std::shared_ptr<const mesh::TriangleMesh>(
        std::make_shared<mesh::TriangleMesh>(std::move(*obj)));
  };

  // The acceleration field (m/s^2 at x, t) of an attractor, vortex or noise
  // force.
  auto accelerationOf = [&](const ForceDef& f) -> Expected<AccelerationField::Fn> {
    switch (f.kind) {
      case ForceKind::kAttractor: {
        // The centre: its position, or the element `of` names (a flock or
        // cloth moves: its centroid is taken at the start of every step).
        auto centre = std::make_shared<Vec3>(f.position.value_or(Vec3::Zero()));
        if (!f.of.empty()) m.centres.push_back({centre, f.of, f.loc, {}});
        const double strength = f.strength, soft = std::max(f.radius, 1e-3);
        const bool inverseSquare = f.falloff == Falloff::kInverseSquare;
        return AccelerationField::Fn([=](const Vec3& x, double) {
          const Vec3 d = *centre - x;
          const double r = std::max(d.norm(), soft);
          return Vec3(d / r * strength / (inverseSquare ? r * r : r));
        });
      }
      case ForceKind::kVortex: {
        const Vec3 c = f.position.value_or(Vec3::Zero()), a = f.axis.normalized();
        const double strength = f.strength;
        return AccelerationField::Fn([=](const Vec3& x, double) {
          const Vec3 r = x - c;
          const Vec3 radial = r - a * a.dot(r);
          const double n = radial.norm();
          return n < 1e-9 ? Vec3(Vec3::Zero()) : Vec3(strength * a.cross(radial) / n);
        });
      }
      case ForceKind::kNoise: {
        particles::NoiseWindDef w;
        w.speed = 1;
        w.scale = f.scale;
        w.frequency = 2 * kPi * f.frequency;
        w.seed = ElementSeed(scene.seed, f.id, "noise-force", size_t(f.loc.line));
        auto field = particles::NoiseWind::Create(w);
        if (!field) return Fail(f.loc, field.error().message, ErrorKind::kInput);
        std::shared_ptr<particles::NoiseWind> n = *field;
        const double strength = f.strength;
        return AccelerationField::Fn(
            [=](const Vec3& x, double t) { return Vec3(strength * n->Velocity(x, t)); });
      }
      case ForceKind::kGravity:
      case ForceKind::kDrag:
        break;
    }
    SYLVA_ASSERT(false);  // gravity and drag are not fields
    return AccelerationField::Fn();
  };

  auto addForces = [&](particles::System& system, const std::vector<ForceDef>& forces, bool windOn,
                       const SourceLoc& loc, const WindGrid* windGrid) -> Status {
    bool drag = false;
    for (const ForceDef& f : forces) {
      switch (f.kind) {
        case ForceKind::kGravity:
          system.AddForce(std::make_shared<particles::Gravity>(f.g));
          break;
        case ForceKind::kDrag:
          drag = true;
          system.AddForce(std::make_shared<WindDrag>(f.quadratic ? 0 : f.k, f.quadratic ? f.k : 0,
                                                     windOn && wind ? windGrid : nullptr));
          break;
        case ForceKind::kAttractor:
        case ForceKind::kVortex:
        case ForceKind::kNoise: {
          auto field = accelerationOf(f);
          if (!field) return field.error();
          system.AddForce(std::make_shared<AccelerationField>(std::move(*field)));
          break;
        }
      }
    }
    if (windOn && wind && !drag)
      diags.Add(Warn(loc,
                     "the wind does not act here: it acts through a <drag> force, and this "
                     "element has none"));
    return {};
  };

  // Particle systems.
  std::map<std::string, ParticleSystem*> byId;
  for (const ParticlesDef& p : scene.particles) {
    auto ps = std::make_unique<ParticleSystem>();
    ps->def = &p;
    ps->system = std::make_unique<particles::System>(options.pool ? 1 : threads);
    if (options.pool) ps->system->UsePool(options.pool);
    switch (p.integrator) {
      case Integrator::kSymplectic:
        ps->integrator = particles::Integrator::kSymplecticEuler;
        break;
      case Integrator::kEuler:
        ps->integrator = particles::Integrator::kExplicitEuler;
        break;
      case Integrator::kRk2:
        ps->integrator = particles::Integrator::kMidpoint;
        break;
      case Integrator::kRk4:
        ps->integrator = particles::Integrator::kRK4;
        break;
      case Integrator::kImplicit:
        ps->integrator = particles::Integrator::kImplicitEuler;
        break;
      case Integrator::kRk45:
        ps->adaptive = true;
        break;
    }
    ps->windGrid->wind = wind;
    if (Status s = addForces(*ps->system, p.forces, p.wind, p.loc, ps->windGrid.get()); !s.ok())
      return s.error();
    if (Status s = m.AddColliders(*ps->system, p.collides, diags); !s.ok()) return s.error();
    if (p.selfCollideRestitution) {
      const double radius = p.emitters.empty() ? 0.05 : std::max(p.emitters[0].radius, 1e-6);
      if (Status s = ps->system->EnableParticleCollisions(radius, *p.selfCollideRestitution);
          !s.ok())
        return Fail(p.loc, s.error().message, ErrorKind::kInput);
    }
    if (p.springs.size() > 1)
      return Fail(p.springs[1].loc, "one <springs> per <particles>", ErrorKind::kInput);
    if (!p.springs.empty()) {
      const SpringsDef& sp = p.springs[0];
      // Nearest and grid scan every living particle at each birth.
      if (sp.between != SpringTopology::kChain && p.max > 20000)
        return Fail(sp.loc,
                    "springs between nearest particles scan them all at each birth: at most "
                    "20000 particles (the <particles> max is " +
                        std::to_string(p.max) + ")",
                    ErrorKind::kInput);
      ps->springsDef = &sp;
      ps->springs = std::make_shared<particles::Springs>();
      ps->system->AddForce(ps->springs);
    }
    for (size_t k = 0; k < p.emitters.size(); ++k) {
      const EmitterDef& e = p.emitters[k];
      const uint64_t seed =
          CounterHash(ElementSeed(scene.seed, p.id, "particles", size_t(p.loc.line)), k);
      const terrain::HeightField* terrain = nullptr;
      const PlantPoints* pts = nullptr;
      if (e.shape == EmitterShape::kTerrain) {
        for (size_t t = 0; t < scene.terrains.size(); ++t)
          if (scene.terrains[t].id == e.of) terrain = &built.terrains[t];
      }
      if (e.shape == EmitterShape::kPlant) {
        const auto it = built.points.find(e.of);
        pts = it == built.points.end() ? nullptr : &it->second;
        const size_t n = !pts                           ? 0
                         : e.part == PlantPart::kTips   ? pts->tips.size()
                         : e.part == PlantPart::kLeaves ? pts->leaves.size()
                                                        : pts->segmentPoints.size();
        if (n == 0)
          return Fail(
              e.loc,
              "the plant '" + e.of + "' has no " +
                  (e.part == PlantPart::kTips     ? std::string("branch tips")
                   : e.part == PlantPart::kLeaves ? std::string("leaves (polygons or surfaces)")
                                                  : std::string("segments")) +
                  " to emit from",
              ErrorKind::kInput);
      }
      if (e.shape == EmitterShape::kTerrain && !terrain)  // the reader checks `of`: a bug
        return Fail(e.loc, "'of=\"" + e.of + "\"' names no terrain");
      auto made = MakeEmitter(e, seed, p.max, terrain, pts);
      if (!made) return made.error();
      Source src;
      src.def = &e;
      src.emitter.emplace(std::move(*made));
      ps->sources.push_back(std::move(src));
    }
    if (p.draw.as == DrawAs::kMesh) {
      auto mesh = loadMesh(p.draw);
      if (!mesh) return mesh.error();
      ps->drawMesh = *mesh;
      if (p.draw.spinDegrees != 0) {
        // Leaves: the plate's drag is four times the system's linear drag.
        for (const ForceDef& f : p.forces)
          if (f.kind == ForceKind::kDrag && !f.quadratic) ps->plateK += 4 * f.k;
        ps->flutter = true;
        ps->leaves = std::make_unique<LeafStates>();
        ps->leafSeed = CounterHash(ElementSeed(scene.seed, p.id, "leaves", size_t(p.loc.line)), 1);
        if (ps->plateK > 0)
          ps->system->AddForce(std::make_shared<PlateDrag>(
              ps->plateK, p.wind && m.hasWind ? &m.wind : nullptr, ps->leaves.get()));
      }
    }
    if (!p.id.empty()) byId[p.id] = ps.get();
    m.systems.push_back(std::move(ps));
  }
  for (auto& ps : m.systems)
    for (const OnDeathDef& d : ps->def->onDeath) ps->onDeath.push_back({byId.at(d.emit), &d});

  // Cloth.
  for (const ClothDef& c : scene.cloths) {
    particles::ClothDef d;
    d.columns = c.columns;
    d.rows = c.rows;
    const Mat3 r = (Eigen::AngleAxisd(c.rotateDegrees.z() * kDegToRad, Vec3::UnitZ()) *
                    Eigen::AngleAxisd(c.rotateDegrees.y() * kDegToRad, Vec3::UnitY()) *
                    Eigen::AngleAxisd(c.rotateDegrees.x() * kDegToRad, Vec3::UnitX()))
                       .toRotationMatrix();
    d.origin = c.position;
    d.u = r * Vec3(c.size.x(), 0, 0);
    d.v = r * Vec3(0, -c.size.y(), 0);
    d.mass = 0.2 * c.size.x() * c.size.y();  // 200 g/m^2: a flag's cotton
    d.stretchCompliance = c.stretch > 0 ? 1 / c.stretch : 0;
    d.bendCompliance = c.bend > 0 ? 1 / c.bend : 1e6;
    d.damping = c.damping;
    d.threads = threads;
    d.pool = options.pool;
    d.solver = c.solver == ClothSolver::kImplicit ? particles::ClothSolver::kImplicit
                                                  : particles::ClothSolver::kXPBD;
    switch (c.pin) {
      case Pin::kTop:
        for (int i = 0; i < c.columns; ++i) d.pinned.push_back(i);
        break;
      case Pin::kLeft:
        for (int j = 0; j < c.rows; ++j) d.pinned.push_back(j * c.columns);
        break;
      case Pin::kCorners:
        d.pinned = {0, c.columns - 1};
        break;
      case Pin::kNone:
        break;
      case Pin::kIds:
        d.pinned = c.pinIds;
        break;
    }
    if (!c.wind || !scene.wind) d.windDrag = d.windLift = 0;
    // Colliders; `with` naming the cloth itself turns on its self-collision,
    // at a thickness of 0.75 of its larger cell side (at least the cell's
    // half diagonal, so a layer cannot slip between two particles of
    // another), with that <collide>'s friction.
    std::vector<particles::Collider> colliders;
    if (Status s = m.CollidersOf(c.collides, c.id, diags, colliders); !s.ok()) return s.error();
    for (const CollideDef& col : c.collides) {
      if (c.id.empty() || std::find(col.with.begin(), col.with.end(), c.id) == col.with.end())
        continue;
      d.thickness = 0.75 * std::max(c.size.x() / (c.columns - 1), c.size.y() / (c.rows - 1));
      d.selfFriction = std::min(col.friction, 1e3);
    }
    auto cloth = particles::Cloth::Create(d);
    if (!cloth) return Fail(c.loc, cloth.error().message, ErrorKind::kInput);
    ClothSheet sheet;
    sheet.def = &c;
    sheet.cloth = std::move(*cloth);
    sheet.windGrid->wind = wind;
    for (particles::Collider& col : colliders) {
      const Status s = sheet.cloth->AddCollider(std::move(col));
      SYLVA_ASSERT(s.ok());  // validated, and never kKill
    }
    // Forces: gravity as the cloth's own, the others through one field of
    // forces on each vertex (drag -k (v - wind) per vertex, as on particles;
    // attractor, vortex and noise as accelerations of the vertex's mass).
    std::vector<AccelerationField::Fn> fields;
    std::vector<std::pair<double, bool>> drags;  // k, quadratic
    for (const ForceDef& f : c.forces) {
      if (f.kind == ForceKind::kGravity) {
        sheet.gravity += f.g;
      } else if (f.kind == ForceKind::kDrag) {
        drags.emplace_back(f.k, f.quadratic);
      } else {
        auto field = accelerationOf(f);
        if (!field) return field.error();
        fields.push_back(std::move(*field));
      }
    }
    if (!fields.empty() || !drags.empty()) {
      const double mass = sheet.cloth->particleMass();
      const double* time = &m.time;
      const Wind* air = c.wind ? wind : nullptr;
      sheet.cloth->SetExternalForce([=](size_t, const Vec3& x, const Vec3& v) {
        Vec3 f = Vec3::Zero();
        for (const AccelerationField::Fn& a : fields) f += mass * a(x, *time);
        if (!drags.empty()) {
          const Vec3 u = air ? Vec3(v - air->At(x, *time)) : v;
          for (const auto& [k, quadratic] : drags) f -= (quadratic ? k * u.norm() : k) * u;
        }
        return f;
      });
    }
    m.cloths.push_back(std::move(sheet));
  }

  // Flocks: boids steering by the flocking rules, held in their bounds.
  for (const FlockDef& f : scene.flocks) {
    Flock flock;
    flock.def = &f;
    flock.system = std::make_unique<particles::System>(options.pool ? 1 : threads);
    if (options.pool) flock.system->UsePool(options.pool);
    particles::FlockingDef fd;
    const Vec3 extent = f.boundsMax - f.boundsMin;
    fd.radius = std::max(1e-3, std::cbrt(extent.prod() / f.count) * 2.5);
    fd.separationRadius = fd.radius * 0.4;
    fd.cohesion = f.cohesion;
    fd.separation = f.separation;
    fd.alignment = f.alignment;
    for (const std::string& id : f.avoid) {
      const auto it = built.meshesOf.find(id);
      if (id == "ground" || it == built.meshesOf.end()) continue;
      for (size_t k : it->second) {
        const BuiltMesh& bm = built.meshes[k];
        if (std::find_if(scene.terrains.begin(), scene.terrains.end(),
                         [&](const TerrainDef& t) { return t.id == id; }) != scene.terrains.end())
          continue;  // terrain: the floor force below
        mesh::Vec3f lo = bm.mesh->positions.empty() ? mesh::Vec3f::Zero() : bm.mesh->positions[0];
        mesh::Vec3f hi = lo;
        for (const mesh::Vec3f& p : bm.mesh->positions) {
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
        for (const draw::Instance& inst : bm.instances) {
          const Eigen::Matrix4d t = inst.transform.cast<double>();
          const double s = t.block<3, 1>(0, 0).norm();
          const Vec3 centre = (t * ((lo + hi) / 2).cast<double>().homogeneous()).head<3>();
          fd.obstacles.push_back({centre, 0.5 * s * double((hi - lo).maxCoeff())});
        }
      }
    }
    if (!fd.obstacles.empty()) {
      fd.avoid = 4 * f.speed;
      fd.avoidDistance = 2;
    }
    auto flocking = particles::Flocking::Create(fd);
    if (!flocking) return Fail(f.loc, flocking.error().message, ErrorKind::kInput);
    flock.system->AddForce(*flocking);
    // Bounds, cruising speed and the floor: steering accelerations.
    const Vec3 lo = f.boundsMin, hi = f.boundsMax;
    const double speed = f.speed;
    const BuiltScene* b = &built;
    const bool floor = !f.avoid.empty();
    flock.system->AddForce(std::make_shared<particles::ForceFunction>(
        [=](const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* force) {
          for (size_t i = 0; i < s.size(); ++i) {
            Vec3 a = Vec3::Zero();
            for (int k = 0; k < 3; ++k) {
              if (x[i][k] < lo[k]) a[k] += 4 * (lo[k] - x[i][k]);
              if (x[i][k] > hi[k]) a[k] -= 4 * (x[i][k] - hi[k]);
            }
            const double sp = v[i].norm();
            if (sp > 1e-9) a += 2 * (speed - sp) * v[i] / sp;
            if (floor) {
              const double ground = b->GroundHeight(x[i].x(), x[i].z()) + 1.5;
              if (x[i].y() < ground) a.y() += 8 * (ground - x[i].y());
            }
            force[i] += s.mass[i] * a;
          }
        }));
    flock.windGrid->wind = wind;  // never prepared: boids sample the exact field
    if (Status s = addForces(*flock.system, f.forces, false, f.loc, nullptr); !s.ok())
      return s.error();
    if (f.wind && wind)
      flock.system->AddForce(std::make_shared<WindDrag>(0.2, 0, flock.windGrid.get()));
    const uint64_t seed = ElementSeed(scene.seed, f.id, "flock", size_t(f.loc.line));
    for (int i = 0; i < f.count; ++i) {
      auto u = [&](uint64_t k) { return ToUnit(CounterHash(seed, uint64_t(i), k)); };
      const Vec3 x = lo + Vec3(u(0), u(1), u(2)).cwiseProduct(hi - lo);
      const Vec3 v = speed * InCone(Vec3::UnitX(), 180, u(3), u(4));
      flock.system->state.Add(x, v, 1.0);
    }
    if (f.draw.as == DrawAs::kMesh && !f.draw.mesh.empty()) {
      auto mesh = loadMesh(f.draw);
      if (!mesh) return mesh.error();
      flock.drawMesh = *mesh;
    } else {
      flock.drawMesh = DartMesh();
    }
    m.flocks.push_back(std::move(flock));
  }
  if (Status s = m.PlaceCentres(); !s.ok()) return s.error();
  for (auto& ps : m.systems)
    if (Status s = m.AddClothColliders(*ps); !s.ok()) return s.error();
  // A cloth colliding with another cloth: the other sheet's triangles, now
  // and before each step, kept a quarter of this sheet's cell away (a sheet
  // has two sides: a vertex resting on the surface itself would pass).
  for (ClothSheet& sheet : m.cloths) {
    const ClothDef& d = *sheet.def;
    const double cell =
        std::max(d.size.x() / std::max(d.columns - 1, 1), d.size.y() / std::max(d.rows - 1, 1));
    const double thickness = std::max(0.25 * cell, 1e-3);
    for (const CollideDef& c : d.collides) {
      for (const std::string& id : c.with) {
        for (size_t k = 0; k < m.cloths.size(); ++k) {
          if (m.cloths[k].def->id != id || &m.cloths[k] == &sheet) continue;
          sheet.others.push_back({k, sheet.cloth->colliders().size(), &c});
          if (Status s = sheet.cloth->AddCollider(ClothAsCollider(m.cloths[k], c),
                                                  std::min(thickness, 1e3));
              !s.ok()) {
            Diagnostic diag = s.error();
            diag.loc = c.loc;
            return diag;
          }
        }
      }
    }
  }
  return sim;
}

// --- drawing -------------------------------------------------------------------

namespace {

Vec3 ColorAt(const DrawDef& d, double age, double lifetime) {
  if (!d.colorEnd) return d.color;
  const double t = std::clamp(lifetime > 0 ? age / lifetime : 0.0, 0.0, 1.0);
  return d.color + t * (*d.colorEnd - d.color);
}

}  // namespace

void Simulation::AddToDrawList(draw::DrawList& list) const {
  const Impl& m = *impl_;
  for (const auto& ps : m.systems) {
    const ParticlesDef& p = *ps->def;
    const ParticleState& st = ps->system->state;
    if (st.size() == 0) continue;
    const DrawDef& d = p.draw;
    if (d.as == DrawAs::kMesh && ps->drawMesh) {
      draw::MeshDraw md;
      md.name = p.id;
      md.mesh = ps->drawMesh;
      md.palette = {mesh::Vec3f(1, 1, 1)};
      // The mesh turns about its own centre.
      mesh::Vec3f lo =
          ps->drawMesh->positions.empty() ? mesh::Vec3f::Zero() : ps->drawMesh->positions[0];
      mesh::Vec3f hi = lo;
      for (const mesh::Vec3f& q : ps->drawMesh->positions) {
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
      const Vec3 pivot = ((lo + hi) / 2).cast<double>();
      for (size_t i = 0; i < st.size(); ++i) {
        const uint64_t h = CounterHash(uint64_t(p.loc.line), st.id[i]);
        Eigen::Affine3d a = Eigen::Affine3d::Identity();
        if (st.invMass[i] == 0) {
          // At rest (stuck where it landed): lying flat, turned at random.
          a.translate(st.position[i] + Vec3(0, 0.005, 0));
          a.rotate(Eigen::AngleAxisd(2 * kPi * ToUnit(Mix64(h ^ 7)), Vec3::UnitY()));
          a.rotate(Eigen::AngleAxisd(-kPi / 2, Vec3::UnitX()));
        } else if (ps->leaves && ps->leaves->count(st.id[i])) {
          // A leaf: its plate normal (the mesh's +Z) as integrated.
          a.translate(st.position[i]);
          a.rotate(Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), ps->leaves->at(st.id[i]).n));
          a.rotate(Eigen::AngleAxisd(2 * kPi * ToUnit(Mix64(h ^ 7)), Vec3::UnitZ()));
        } else {
          // Tumbling: a turn about an axis of the particle's own, growing
          // with age.
          const Vec3 axis = InCone(Vec3::UnitY(), 180, ToUnit(h), ToUnit(Mix64(h)));
          const double angle =
              d.spinDegrees * kDegToRad * st.age[i] + 2 * kPi * ToUnit(Mix64(h ^ 7));
          a.translate(st.position[i]);
          a.rotate(Eigen::AngleAxisd(angle, axis));
        }
        a.scale(d.size);
        a.translate(-pivot);
        md.instances.push_back(
            {a.matrix().cast<float>(), ColorAt(d, st.age[i], st.lifetime[i]).cast<float>()});
      }
      list.meshes.push_back(std::move(md));
      continue;
    }
    if (d.as == DrawAs::kTrails) {
      std::vector<mesh::Vec3f> colors(st.size());
      for (size_t i = 0; i < st.size(); ++i)
        colors[i] = ColorAt(d, st.age[i], st.lifetime[i]).cast<float>();
      auto trails = draw::Trails(st.position, st.velocity, 0.06, colors, {}, 0.3f, p.id);
      SYLVA_ASSERT(trails.ok());  // one velocity and one colour a particle
      list.lines.push_back(std::move(*trails));
      continue;
    }
    draw::PointStyle style;
    style.name = p.id;
    style.size = float(d.size);
    style.color = d.color.cast<float>();
    style.alpha = float(d.alpha);
    style.blend = d.blend == Blend::kAdditive ? draw::Blend::kAdditive : draw::Blend::kAlpha;
    std::vector<mesh::Vec3f> colors;
    if (d.colorEnd) {
      colors.resize(st.size());
      for (size_t i = 0; i < st.size(); ++i)
        colors[i] = ColorAt(d, st.age[i], st.lifetime[i]).cast<float>();
    }
    auto sprites = draw::PointSprites(st.position, style, colors);
    SYLVA_ASSERT(sprites.ok());  // one colour a particle, or none
    list.sprites.push_back(std::move(*sprites));
  }
  for (const ClothSheet& c : m.cloths) {
    auto sheet = draw::SheetMesh(c.cloth->positions(), c.cloth->triangles());
    SYLVA_ASSERT(sheet.ok());  // the cloth's own triangles index its vertices
    draw::MeshDraw md;
    md.name = c.def->id;
    md.mesh = std::make_shared<const mesh::TriangleMesh>(std::move(*sheet));
    md.palette = {c.def->color.cast<float>()};
    md.instances.push_back({});
    list.meshes.push_back(std::move(md));
  }
  for (const Flock& f : m.flocks) {
    const ParticleState& st = f.system->state;
    if (f.def->draw.as == DrawAs::kPoints || f.def->draw.as == DrawAs::kSprites) {
      draw::PointStyle style;
      style.name = f.def->id;
      style.size = float(f.def->draw.size);
      style.color = f.def->draw.color.cast<float>();
      auto sprites = draw::PointSprites(st.position, style);
      SYLVA_ASSERT(sprites.ok());
      list.sprites.push_back(std::move(*sprites));
      continue;
    }
    draw::MeshDraw md;
    md.name = f.def->id;
    md.mesh = f.drawMesh;
    md.palette = {mesh::Vec3f(1, 1, 1)};
    auto instances = draw::FacingInstances(st.position, st.velocity, f.def->draw.size,
                                           f.def->draw.color.cast<float>());
    SYLVA_ASSERT(instances.ok());  // one velocity a boid
    md.instances = std::move(*instances);
    list.meshes.push_back(std::move(md));
  }
}

size_t Simulation::Count() const {
  size_t n = 0;
  for (const auto& ps : impl_->systems) n += ps->system->state.size();
  for (const ClothSheet& c : impl_->cloths) n += c.cloth->positions().size();
  for (const Flock& f : impl_->flocks) n += f.system->state.size();
  return n;
}

void Simulation::WriteCsv(std::ostream& out) const {
  char line[320];
  out << "system,id,x,y,z,vx,vy,vz,age\n";
  auto row = [&](const std::string& system, uint64_t id, const Vec3& x, const Vec3& v, double age) {
    std::snprintf(line, sizeof line, "%s,%llu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", system.c_str(),
                  static_cast<unsigned long long>(id), x.x(), x.y(), x.z(), v.x(), v.y(), v.z(),
                  age);
    out << line;
  };
  for (size_t k = 0; k < impl_->systems.size(); ++k) {
    const auto& ps = impl_->systems[k];
    const std::string name = ps->def->id.empty() ? "particles" + std::to_string(k) : ps->def->id;
    const ParticleState& st = ps->system->state;
    for (size_t i = 0; i < st.size(); ++i)
      row(name, st.id[i], st.position[i], st.velocity[i], st.age[i]);
  }
  for (size_t k = 0; k < impl_->cloths.size(); ++k) {
    const ClothSheet& c = impl_->cloths[k];
    const std::string name = c.def->id.empty() ? "cloth" + std::to_string(k) : c.def->id;
    for (size_t i = 0; i < c.cloth->positions().size(); ++i)
      row(name, i, c.cloth->positions()[i], c.cloth->velocities()[i], impl_->time);
  }
  for (size_t k = 0; k < impl_->flocks.size(); ++k) {
    const Flock& f = impl_->flocks[k];
    const std::string name = f.def->id.empty() ? "flock" + std::to_string(k) : f.def->id;
    const ParticleState& st = f.system->state;
    for (size_t i = 0; i < st.size(); ++i)
      row(name, st.id[i], st.position[i], st.velocity[i], st.age[i]);
  }
}

}  // namespace sylva::scene
