#include "scene/build.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/rng.h"
#include "plant/grow_together.h"
#include "plant/surface_library.h"
#include "scene/plants.h"

namespace sylva::scene {
namespace {

Diagnostic AtElement(const SourceLoc& loc, std::string message,
                     Severity severity = Severity::kError) {
  Diagnostic d = MakeError(loc, std::move(message));
  d.severity = severity;
  return d;
}

// The spec as the scene grows it: its threads, detail, to the mesh.
plant::PlantSpec ForScene(plant::PlantSpec spec, const BuildOptions& options) {
  spec.threads = options.threads;
  spec.pool = options.pool;
  spec.detail.sides = options.sides;
  spec.until = plant::Stage::kMesh;
  return spec;
}

// A grown plant, or its diagnostics with a note at the scene element.
std::optional<plant::Plant> Take(plant::PlantResult r, const SourceLoc& where, const char* element,
                                 DiagnosticList& diags) {
  for (Diagnostic& d : r.diagnostics.items) diags.Add(std::move(d));
  if (!r.plant || !r.diagnostics.items.empty()) {
    Diagnostic note = MakeError(where, std::string("in the grammar of this <") + element + ">");
    note.severity = Severity::kNote;
    diags.Add(std::move(note));
  }
  return std::move(r.plant);
}

std::optional<plant::Plant> Grow(const plant::PlantSpec& spec, const BuildOptions& options,
                                 const SourceLoc& where, const char* element,
                                 DiagnosticList& diags) {
  return Take(plant::BuildPlant(ForScene(spec, options)), where, element, diags);
}

// Where a <plant> stands: on the ground at x, z unless its y is given.
Vec3 PlacedAt(const PlantDef& p, const BuiltScene& built) {
  Vec3 at = p.position;
  if (!p.positionHasY) at.y() = built.GroundHeight(at.x(), at.z());
  return at;
}

// A plant's grammar, parsed alone (nullopt on an error: it is reported
// when the plant grows).
std::optional<lsys::Grammar> ParsedGrammar(const plant::PlantSpec& spec) {
  plant::PlantSpec s = spec;
  s.until = plant::Stage::kGrammar;
  plant::PlantResult r = plant::BuildPlant(s);
  if (!r.plant) return std::nullopt;
  return std::move(r.plant->grammar);
}

bool SameStatement(const lsys::EnvironmentStatement& a, const lsys::EnvironmentStatement& b) {
  if (a.kind != b.kind || a.items.size() != b.items.size()) return false;
  for (size_t i = 0; i < a.items.size(); ++i) {
    const auto &x = a.items[i], &y = b.items[i];
    if (x.name != y.name || x.values != y.values || x.call != y.call || x.keyValue != y.keyValue)
      return false;
  }
  return true;
}

// The <plant>s whose grammars say `environment: light` grow together in one
// light grid, in world coordinates (metres), so that they compete for
// light (plant/grow_together.h). The grid is the first such plant's
// statement (its boxes read in world coordinates); a plant whose statement
// differs is warned about. Results by plant index; the others are unset.
std::vector<std::optional<plant::PlantResult>> GrowInSharedLight(const Scene& scene,
                                                                 const BuiltScene& built,
                                                                 const BuildOptions& options,
                                                                 DiagnosticList& diags) {
  std::vector<std::optional<plant::PlantResult>> out(scene.plants.size());
  std::vector<size_t> which;
  std::vector<plant::PlantSpec> specs;
  std::vector<plant::Placement> placements;
  std::unique_ptr<plant::Environment> shared;
  lsys::EnvironmentStatement first;
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const PlantDef& p = scene.plants[i];
    const plant::PlantSpec spec = SpecFor(p);
    const std::optional<lsys::Grammar> g = ParsedGrammar(spec);
    if (!g || !g->environment || g->environment->kind != "light") continue;
    const lsys::EnvironmentStatement& st = *g->environment;
    if (!shared) {
      auto env = plant::MakeEnvironment(st, *g);
      if (!env) continue;  // reported when the plant grows alone
      shared = std::move(*env);
      first = st;
    } else if (!SameStatement(st, first)) {
      diags.Add(AtElement(
          p.loc,
          "this plant's 'environment: light' (" + st.loc.file + ":" + std::to_string(st.loc.line) +
              ") differs from the first light plant's (" + first.loc.file + ":" +
              std::to_string(first.loc.line) + "): the scene's plants share that one's light grid",
          Severity::kWarning));
    }
    which.push_back(i);
    specs.push_back(ForScene(spec, options));
    placements.push_back(plant::Placement{PlacedAt(p, built), p.rotateDegrees, p.scale});
  }
  if (which.empty()) return out;
  std::vector<plant::PlantResult> grown = plant::GrowTogether(specs, placements, *shared);
  for (size_t k = 0; k < which.size(); ++k) out[which[k]] = std::move(grown[k]);
  return out;
}

// The ground under a plant at `at`, turned by `yawDegrees` about Y and
// scaled by `scale` (draw::Transform), in the plant's own coordinates.
// Points into `built`: use it while the plants grow.
plant::Ground GroundUnder(const BuiltScene& built, const Vec3& at, double yawDegrees,
                          double scale) {
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(yawDegrees * 3.14159265358979323846 / 180, Vec3::UnitY())
          .toRotationMatrix();
  auto world = [r, at, scale](double x, double z) {
    return Vec3(at + r * (scale * Vec3(x, 0, z)));
  };
  plant::Ground g;
  g.height = [&built, world, at, scale](double x, double z) {
    const Vec3 w = world(x, z);
    return (built.GroundHeight(w.x(), w.z()) - at.y()) / scale;
  };
  g.normal = [&built, world, r](double x, double z) {
    const Vec3 w = world(x, z);
    for (const terrain::HeightField& t : built.terrains)
      if (t.Contains(w.x(), w.z())) return Vec3(r.transpose() * t.Normal(w.x(), w.z()));
    return Vec3(0, 1, 0);
  };
  return g;
}

// The grammar's environment reads the plant's placement (terrain, light).
bool ReadsPlacement(const lsys::Grammar& g) {
  return g.environment && (g.environment->kind == "terrain" || g.environment->kind == "light");
}

// Box of a mesh through a transform.
void GrowBounds(const mesh::TriangleMesh& m, const draw::Mat4f& t, Vec3& lo, Vec3& hi, bool& any) {
  for (const mesh::Vec3f& p : m.positions) {
    const Vec3 w = (t.cast<double>() * p.cast<double>().homogeneous()).head<3>();
    lo = any ? lo.cwiseMin(w) : w;
    hi = any ? hi.cwiseMax(w) : w;
    any = true;
  }
}

std::shared_ptr<mesh::TriangleMesh> TerrainMeshOf(const terrain::TerrainMesh& t) {
  auto m = std::make_shared<mesh::TriangleMesh>();
  const size_t n = t.positions.size() / 3;
  m->positions.resize(n);
  m->normals.resize(n);
  m->uvs.resize(n);
  for (size_t i = 0; i < n; ++i) {
    m->positions[i] =
        mesh::Vec3f(t.positions[3 * i], t.positions[3 * i + 1], t.positions[3 * i + 2]);
    m->normals[i] = mesh::Vec3f(t.normals[3 * i], t.normals[3 * i + 1], t.normals[3 * i + 2]);
    m->uvs[i] = mesh::Vec2f(t.positions[3 * i], t.positions[3 * i + 2]);
  }
  m->indices = t.indices;
  m->material.assign(t.indices.size() / 3, 0);
  return m;
}

// The factor that makes the mesh `height` metres tall (its y extent).
double HeightScale(const mesh::TriangleMesh& m, double height, const SourceLoc& loc,
                   DiagnosticList& diags) {
  float lo = 0, hi = 0;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    lo = i ? std::min(lo, m.positions[i].y()) : m.positions[i].y();
    hi = i ? std::max(hi, m.positions[i].y()) : m.positions[i].y();
  }
  if (!(hi > lo)) {
    diags.Add(AtElement(loc, "'height' cannot scale a plant with no vertical extent; drawn at 1:1",
                        Severity::kWarning));
    return 1;
  }
  return height / double(hi - lo);
}

// The surface meshes `g` places (`~leaf`), found as the plant's
// tessellation found them; empty when it places none.
std::unordered_map<std::string, mesh::TriangleMesh> SurfacesOf(const plant::Plant& p,
                                                               const plant::PlantSpec& spec) {
  if (p.geometry.surfaces.empty()) return {};
  plant::SurfaceLibrary library(p.grammar.path, spec.surfacePath, spec.readFile);
  if (!library.LoadFor(p.geometry, p.grammar).ok()) return {};  // the mesh was built: never
  return library.meshes();
}

}  // namespace

void AddPlantPoints(const mesh::PlantGeometry& g, const draw::Mat4f& t,
                    const std::unordered_map<std::string, mesh::TriangleMesh>& surfaces,
                    PlantPoints& out) {
  const Eigen::Matrix4d m = t.cast<double>();
  auto world = [&](const Vec3& p) { return Vec3((m * p.homogeneous()).head<3>()); };
  struct Hash {
    size_t operator()(const Vec3& v) const {
      return std::hash<double>()(v.x()) ^ (std::hash<double>()(v.y()) << 1) ^
             (std::hash<double>()(v.z()) << 2);
    }
  };
  std::unordered_map<Vec3, int, Hash> starts;
  for (const mesh::Segment& s : g.segments) starts[s.start] = 1;
  const double scale = m.block<3, 1>(0, 0).norm();
  for (const mesh::Segment& s : g.segments) {
    if (!starts.count(s.end)) out.tips.push_back(world(s.end));
    out.segmentPoints.push_back(world((s.start + s.end) / 2));
    out.segmentLengths.push_back((s.end - s.start).norm() * scale);
    out.capsules.push_back(particles::Capsule{
        world(s.start), world(s.end), double(std::max(s.radiusStart, s.radiusEnd)) * scale});
  }
  for (const mesh::Polygon& p : g.polygons) {
    if (p.vertices.empty()) continue;
    Vec3 c = Vec3::Zero();
    for (const Vec3& v : p.vertices) c += v;
    out.leaves.push_back(world(c / double(p.vertices.size())));
    for (size_t k = 1; k + 1 < p.vertices.size(); ++k)
      out.leafTriangles.push_back(
          {world(p.vertices[0]), world(p.vertices[k]), world(p.vertices[k + 1])});
  }
  for (const mesh::SurfaceInstance& s : g.surfaces) {
    out.leaves.push_back(world(s.position));
    const auto found = surfaces.find(s.name);
    if (found == surfaces.end()) continue;
    // Placed as the tessellator places it: scaled along its own axes, then
    // in the turtle's frame (left, heading, up) at its position.
    const mesh::TriangleMesh& sm = found->second;
    auto place = [&](const mesh::Vec3f& p) {
      const Vec3 q = p.cast<double>().cwiseProduct(s.scale);
      return world(s.position + q.x() * s.frame.left + q.y() * s.frame.heading +
                   q.z() * s.frame.up);
    };
    for (size_t k = 0; k + 2 < sm.indices.size(); k += 3)
      out.leafTriangles.push_back({place(sm.positions[sm.indices[k]]),
                                   place(sm.positions[sm.indices[k + 1]]),
                                   place(sm.positions[sm.indices[k + 2]])});
  }
  for (const mesh::Sphere& s : g.spheres) {
    // A sphere (@O: a bud, a fruit) is an organ where it sits, as a surface
    // is: a leaf point; it collides as a capsule of no length.
    out.leaves.push_back(world(s.center));
    out.capsules.push_back(particles::Capsule{world(s.center), world(s.center), s.radius * scale});
  }
  for (const mesh::ContourTube& tube : g.tubes) {
    // A generalized cylinder with a contour (a leaf blade, a petal, a
    // shell): its quads collide as two triangles each, as EmitTube draws
    // them; the stretches between its ring centres are segments, its
    // centre a leaf point, its last ring's centre a tip.
    const size_t R = tube.rings(), W = tube.ringSize;
    if (R < 2 || W < 2) continue;
    const size_t around = tube.closed ? W - 1 : W;  // a closed ring repeats its first point
    std::vector<Vec3> centre(R, Vec3::Zero());
    Vec3 all = Vec3::Zero();
    for (size_t i = 0; i < R; ++i) {
      for (size_t j = 0; j < around; ++j) centre[i] += tube.points[i * W + j];
      all += centre[i];
      centre[i] /= double(around);
    }
    out.leaves.push_back(world(all / double(R * around)));
    for (size_t i = 0; i + 1 < R; ++i) {
      out.segmentPoints.push_back(world((centre[i] + centre[i + 1]) / 2));
      out.segmentLengths.push_back((centre[i + 1] - centre[i]).norm() * scale);
      for (size_t j = 0; j + 1 < W; ++j) {
        const size_t a = i * W + j, b = a + 1, d = a + W, c = d + 1;
        const Vec3 pa = world(tube.points[a]), pc = world(tube.points[c]);
        out.leafTriangles.push_back({pa, world(tube.points[b]), pc});
        out.leafTriangles.push_back({pa, pc, world(tube.points[d])});
      }
    }
    if (!starts.count(centre[R - 1])) out.tips.push_back(world(centre[R - 1]));
  }
}

terrain::TerrainDef TerrainDefOf(const TerrainDef& t, uint64_t seed) {
  terrain::TerrainDef d;
  d.sizeX = t.size.x();
  d.sizeZ = t.size.y();
  d.resolution = t.resolution;
  d.height = t.noise == NoiseKind::kFlat ? 0 : t.height;
  d.noise = t.noise == NoiseKind::kFbm             ? terrain::NoiseKind::kFbm
            : t.noise == NoiseKind::kRidged        ? terrain::NoiseKind::kRidged
            : t.noise == NoiseKind::kDiamondSquare ? terrain::NoiseKind::kDiamondSquare
                                                   : terrain::NoiseKind::kFlat;
  d.octaves = t.octaves;
  d.lacunarity = t.lacunarity;
  d.gain = t.gain;
  d.seed = seed;
  return d;
}

double BuiltScene::GroundHeight(double x, double z) const {
  for (const terrain::HeightField& t : terrains)
    if (t.Contains(x, z)) return t.Height(x, z);
  return 0;
}

std::vector<Vec2> ScatterPoisson(const ForestDef& f, uint64_t seed) {
  // Dart throwing with a background grid of cells at least r wide, each a
  // list of the points in it, so that every point within r of a candidate
  // lies in its 3 x 3 cells: candidate k is drawn from the counter-based
  // stream (seed, k), so the result does not depend on anything but the def.
  // The grid has at most max(2^22, 4 count) cells whatever the area and r (a tiny r
  // over a wide area once overflowed the cell count; an r of 0 divided by
  // 0); the grid only speeds the test up, so its size changes no result.
  const double kMaxCells = std::max(double(1 << 22), 4.0 * double(f.count));
  const Vec2 a0(f.area[0], f.area[1]), a1(f.area[2], f.area[3]);
  const Vec2 extent = a1 - a0;
  const double r = f.minDistance > 0
                       ? f.minDistance
                       : 0.7 * std::sqrt(extent.x() * extent.y() / std::max(1, f.count));
  double cell = std::max(r, extent.maxCoeff() / kMaxCells);
  if (!(cell > 0)) cell = 1;  // r = 0 (or an underflow): any grid does
  while (std::ceil(extent.x() / cell) * std::ceil(extent.y() / cell) > kMaxCells) cell *= 2;
  const int nx = std::max(1, int(std::ceil(extent.x() / cell)));
  const int nz = std::max(1, int(std::ceil(extent.y() / cell)));
  std::vector<int> head(size_t(nx) * size_t(nz), -1);  // a cell's last point
  std::vector<int> next;                               // the point before it in its cell
  std::vector<Vec2> out;
  const uint64_t attempts = uint64_t(f.count) * 30 + 100;
  for (uint64_t k = 0; k < attempts && int(out.size()) < f.count; ++k) {
    const Vec2 p(a0.x() + extent.x() * ToUnit(CounterHash(seed, 0x5ca7, k, 0)),
                 a0.y() + extent.y() * ToUnit(CounterHash(seed, 0x5ca7, k, 1)));
    const int ci = std::clamp(int((p.x() - a0.x()) / cell), 0, nx - 1);
    const int cj = std::clamp(int((p.y() - a0.y()) / cell), 0, nz - 1);
    bool ok = true;
    for (int j = std::max(0, cj - 1); ok && j <= std::min(nz - 1, cj + 1); ++j)
      for (int i = std::max(0, ci - 1); ok && i <= std::min(nx - 1, ci + 1); ++i)
        for (int q = head[size_t(j) * size_t(nx) + size_t(i)]; ok && q >= 0; q = next[size_t(q)])
          if ((out[size_t(q)] - p).norm() < r) ok = false;
    if (!ok) continue;
    int& h = head[size_t(cj) * size_t(nx) + size_t(ci)];
    next.push_back(h);
    h = int(out.size());
    out.push_back(p);
  }
  return out;
}

// A transform is drawn in floats: past about 3e38 it is not a number.
constexpr const char* kBeyondFloat =
    "the position, scale or height put this plant beyond what a float holds (about 3e38)";

BuildResult Build(const Scene& scene, const BuildOptions& options) {
  BuildResult result;
  DiagnosticList& diags = result.diagnostics;
  BuiltScene built;
  bool any = false;

  for (size_t i = 0; i < scene.terrains.size(); ++i) {
    const TerrainDef& t = scene.terrains[i];
    const uint64_t seed = t.seed.value_or(ElementSeed(scene.seed, t.id, "terrain", i));
    Expected<terrain::HeightField> field = terrain::HeightField::Create(TerrainDefOf(t, seed));
    if (!field) {
      Diagnostic d = field.error();
      d.loc = t.loc;
      diags.Add(std::move(d));
      continue;
    }
    Expected<terrain::TerrainMesh> arrays = field->MakeMesh();
    if (!arrays) {
      Diagnostic d = arrays.error();
      d.loc = t.loc;
      diags.Add(std::move(d));
      continue;
    }
    BuiltMesh m;
    m.mesh = TerrainMeshOf(*arrays);
    m.palette = {t.color.cast<float>()};
    m.instances.push_back({});
    m.castsShadow = false;
    m.loc = t.loc;
    GrowBounds(*m.mesh, m.instances[0].transform, built.lo, built.hi, any);
    built.trianglesDrawn += m.mesh->triangleCount();
    if (!t.id.empty()) built.meshesOf[t.id].push_back(built.meshes.size());
    built.meshes.push_back(std::move(m));
    built.terrains.push_back(std::move(*field));
  }
  // `diags` is result.diagnostics: moving it onto itself emptied it, so a
  // terrain error left the command failing without a word.
  if (diags.HasErrors()) return result;

  std::vector<std::optional<plant::PlantResult>> inLight =
      GrowInSharedLight(scene, built, options, diags);
  for (size_t pi = 0; pi < scene.plants.size(); ++pi) {
    const PlantDef& p = scene.plants[pi];
    plant::PlantSpec spec = SpecFor(p);
    const Vec3 at = PlacedAt(p, built);
    // `environment: terrain` reads the terrain under the plant, in the
    // plant's coordinates (at its `scale`: `height` rescales after growth).
    spec.ground = GroundUnder(built, at, p.rotateDegrees, p.scale);
    std::optional<plant::Plant> grown =
        inLight[pi] ? Take(std::move(*inLight[pi]), p.grammarLoc, "plant", diags)
                    : Grow(spec, options, p.grammarLoc, "plant", diags);
    if (!grown) continue;
    spec.ground.reset();  // it points into `built`; the kept spec is for tessellation
    if (p.height && ReadsPlacement(grown->grammar)) {
      diags.Add(AtElement(p.loc,
                          "'height' rescales this plant after it grew: its grammar's "
                          "'environment: " +
                              grown->grammar.environment->kind + "' read the scene at scale " +
                              std::to_string(p.scale) + ", not at the height's",
                          Severity::kWarning));
    }
    BuiltMesh m;
    m.mesh = std::make_shared<mesh::TriangleMesh>(std::move(grown->mesh));
    m.palette = grown->palette;
    m.spec = spec;
    const double unit = p.height ? HeightScale(*m.mesh, *p.height, p.loc, diags) : 1;
    m.instances.push_back({draw::Transform(at, p.rotateDegrees, p.scale * unit), {1, 1, 1}});
    m.loc = p.loc;
    if (!m.instances[0].transform.allFinite()) {
      diags.Add(AtElement(p.loc, kBeyondFloat));
      continue;
    }
    GrowBounds(*m.mesh, m.instances[0].transform, built.lo, built.hi, any);
    built.trianglesDrawn += m.mesh->triangleCount();
    if (!p.id.empty()) {
      AddPlantPoints(grown->geometry, m.instances[0].transform, SurfacesOf(*grown, spec),
                     built.points[p.id]);
      built.meshesOf[p.id].push_back(built.meshes.size());
    }
    m.plant = std::make_shared<plant::Plant>(std::move(*grown));
    built.meshes.push_back(std::move(m));
  }

  for (size_t fi = 0; fi < scene.forests.size(); ++fi) {
    const ForestDef& f = scene.forests[fi];
    const uint64_t forestSeed = f.seed.value_or(ElementSeed(scene.seed, f.id, "forest", fi));
    const std::vector<Vec2> spots = ScatterPoisson(f, forestSeed);
    if (int(spots.size()) < f.count)
      diags.Add(AtElement(f.loc,
                          "placed " + std::to_string(spots.size()) + " of " +
                              std::to_string(f.count) +
                              " trees: the area is too small for min-distance",
                          Severity::kWarning));
    const terrain::HeightField* on = nullptr;
    for (size_t i = 0; i < scene.terrains.size(); ++i)
      if (!f.on.empty() && scene.terrains[i].id == f.on) on = &built.terrains[i];
    const int variants = std::min<int>(f.variants, std::max<int>(1, int(spots.size())));
    const size_t first = built.meshes.size();
    std::vector<double> unit;
    std::vector<mesh::PlantGeometry> geometry;
    std::vector<std::unordered_map<std::string, mesh::TriangleMesh>> surfaces;
    for (int v = 0; v < variants; ++v) {
      const plant::PlantSpec spec = SpecFor(f, forestSeed, v);
      std::optional<plant::Plant> grown = Grow(spec, options, f.grammarLoc, "forest", diags);
      if (!grown) break;
      if (v == 0 && ReadsPlacement(grown->grammar)) {
        diags.Add(AtElement(f.loc,
                            "a forest grows each variant once, alone, and places it many times: "
                            "its grammar's 'environment: " +
                                grown->grammar.environment->kind +
                                "' read flat ground at y = 0 and the variant's own light, not "
                                "what is around each tree",
                            Severity::kWarning));
      }
      BuiltMesh m;
      m.mesh = std::make_shared<mesh::TriangleMesh>(std::move(grown->mesh));
      m.palette = grown->palette;
      m.loc = f.loc;
      m.spec = spec;
      unit.push_back(f.height ? HeightScale(*m.mesh, *f.height, f.loc, diags) : 1);
      if (!f.id.empty()) {
        geometry.push_back(grown->geometry);
        surfaces.push_back(SurfacesOf(*grown, spec));
        built.meshesOf[f.id].push_back(built.meshes.size());
      }
      m.plant = std::make_shared<plant::Plant>(std::move(*grown));
      built.meshes.push_back(std::move(m));
    }
    if (int(built.meshes.size() - first) != variants) continue;
    for (size_t k = 0; k < spots.size(); ++k) {
      const uint64_t h = CounterHash(forestSeed, 0xf0e57, k);
      const int v = int(h % uint64_t(variants));
      const double yaw = 360 * ToUnit(CounterHash(forestSeed, 0xf0e57, k, 1));
      const double s =
          unit[size_t(v)] * (f.scale.x() + (f.scale.y() - f.scale.x()) *
                                               ToUnit(CounterHash(forestSeed, 0xf0e57, k, 2)));
      const double y = on ? on->Height(spots[k].x(), spots[k].y()) : 0;
      BuiltMesh& m = built.meshes[first + size_t(v)];
      m.instances.push_back(
          {draw::Transform(Vec3(spots[k].x(), y, spots[k].y()), yaw, s), {1, 1, 1}});
      if (!m.instances.back().transform.allFinite()) {
        diags.Add(AtElement(f.loc, kBeyondFloat));
        break;
      }
      GrowBounds(*m.mesh, m.instances.back().transform, built.lo, built.hi, any);
      built.trianglesDrawn += m.mesh->triangleCount();
      if (!f.id.empty())
        AddPlantPoints(geometry[size_t(v)], m.instances.back().transform, surfaces[size_t(v)],
                       built.points[f.id]);
    }
  }

  if (!diags.HasErrors()) result.scene = std::move(built);
  return result;
}

Expected<size_t> DetailForView(BuiltScene& built, const mesh::ScreenView& view,
                               DiagnosticList& diagnostics) {
  size_t drawn = 0;
  for (BuiltMesh& m : built.meshes) {
    if (!m.plant || m.instances.empty()) {
      drawn += m.mesh->triangleCount() * m.instances.size();
      continue;
    }
    // The instance that needs the most detail: the most pixels per unit at
    // its origin, times its scale.
    size_t best = 0;
    double bestDensity = -1;
    for (size_t i = 0; i < m.instances.size(); ++i) {
      const Eigen::Matrix4d t = m.instances[i].transform.cast<double>();
      const double density =
          mesh::PixelsPerUnit(view, t.block<3, 1>(0, 3)) * t.block<3, 1>(0, 0).norm();
      if (density > bestDensity) {
        bestDensity = density;
        best = i;
      }
    }
    plant::PlantSpec spec = m.spec;
    spec.view = view;
    spec.view->viewProjection = view.viewProjection * m.instances[best].transform.cast<double>();
    spec.cull = false;
    // The plant's own mesh was moved to m.mesh; Tessellate fills it again.
    if (Status s = plant::Tessellate(*m.plant, spec, diagnostics); !s.ok()) {
      Diagnostic d = s.error();
      if (d.loc.file.empty()) d.loc = m.loc;
      return d;
    }
    drawn += m.plant->mesh.triangleCount() * m.instances.size();
    m.drawMesh = std::make_shared<mesh::TriangleMesh>(std::move(m.plant->mesh));
    m.plant->mesh = mesh::TriangleMesh();
  }
  return drawn;
}

draw::DrawList MakeDrawList(const Scene& scene, const BuiltScene& built) {
  draw::DrawList list;
  for (const LightDef& l : scene.lights) {
    const draw::Vec3f c = l.color.cast<float>();
    const float i = float(l.intensity);
    switch (l.type) {
      case LightType::kSun:
        list.lights.push_back(draw::Light::Sun(l.direction.cast<float>(), c, i));
        break;
      case LightType::kAmbient:
        list.lights.push_back(draw::Light::Ambient(c, i));
        break;
      case LightType::kPoint:
        list.lights.push_back(draw::Light::Point(l.position.cast<float>(), c, i));
        break;
    }
  }
  if (scene.sky) {
    list.sky = draw::Sky{scene.sky->top.cast<float>(), scene.sky->horizon.cast<float>()};
    list.background = list.sky->horizon;
  }
  for (const BuiltMesh& m : built.meshes) {
    if (m.instances.empty()) continue;
    draw::MeshDraw d;
    d.mesh = m.drawMesh ? m.drawMesh : m.mesh;
    d.palette = m.palette;
    d.instances = m.instances;
    d.castsShadow = m.castsShadow;
    list.meshes.push_back(std::move(d));
  }
  return list;
}

}  // namespace sylva::scene
