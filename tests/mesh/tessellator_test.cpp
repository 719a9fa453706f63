#include "mesh/tessellator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>

#include "core/atomic_file.h"
#include "mesh/export.h"
#include "plant/plant_test_util.h"

namespace sylva::mesh {
namespace {

PlantGeometry Draw(const std::string& text, int steps = -1) {
  auto p = testing::PlantFromText(text, steps);
  return p ? std::move(p->geometry) : PlantGeometry{};
}

PlantGeometry DrawFile(const std::string& name, int steps = -1) {
  auto p = testing::PlantFromFile("abop/" + name + ".lsys", steps);
  return p ? std::move(p->geometry) : PlantGeometry{};
}

TriangleMesh Mesh(const PlantGeometry& g, int sides = 8) {
  TriangleMesh m;
  TessellateOptions opt;
  opt.detail.sides = sides;
  EXPECT_TRUE(Tessellate(g, opt, m).ok());
  return m;
}

// Welds vertices at equal positions and checks that every edge is shared by
// exactly two triangles with opposite directions (a closed, consistently
// oriented 2-manifold). Returns V - E + F, or a large negative value on failure.
long EulerCharacteristic(const TriangleMesh& m, std::string* why) {
  std::map<std::tuple<float, float, float>, uint32_t> weld;
  std::vector<uint32_t> id(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    auto key = std::make_tuple(m.positions[i].x(), m.positions[i].y(), m.positions[i].z());
    id[i] = weld.emplace(key, uint32_t(weld.size())).first->second;
  }
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    for (int e = 0; e < 3; ++e) {
      uint32_t a = id[m.indices[3 * t + e]], b = id[m.indices[3 * t + (e + 1) % 3]];
      if (++directed[{a, b}] > 1) {
        *why = "directed edge used twice (inconsistent orientation or non-manifold)";
        return -1000000;
      }
    }
  }
  for (const auto& [e, n] : directed) {
    if (!directed.count({e.second, e.first})) {
      *why = "boundary edge: the surface is not closed";
      return -1000000;
    }
  }
  return long(weld.size()) - long(directed.size() / 2) + long(m.triangleCount());
}

TEST(Tessellator, TriangleCountsFollowTheDetailExactly) {
  PlantGeometry g = Draw("axiom: FFF\n");
  for (int sides : {3, 5, 8, 16, 64}) {
    TriangleMesh m = Mesh(g, sides);
    EXPECT_EQ(m.triangleCount(), TubeTriangles(3, sides)) << sides << " sides";
    EXPECT_EQ(m.vertexCount(), size_t(4 * (sides + 1) + 2 * (sides + 1))) << sides << " sides";
    EXPECT_EQ(Validate(m), "") << sides;
  }
}

TEST(Tessellator, EachTubeIsAClosedTwoManifold) {
  for (const char* text :
       {"axiom: FFF\n", "angle: 30\naxiom: F+F-F&F/F^F\n", "axiom: !(2)F!(1)F\n"}) {
    TriangleMesh m = Mesh(Draw(text), 8);
    std::string why;
    EXPECT_EQ(EulerCharacteristic(m, &why), 2) << text << why;
  }
}

TEST(Tessellator, BranchesShareRingsAlongTheirAxis) {
  // F[+F]F: the trunk is one chain of 2 segments (the ring at the joint is
  // shared), the branch another: 2 closed components.
  PlantGeometry g = Draw("axiom: F[+F]F\n");
  TriangleMesh m = Mesh(g, 6);
  EXPECT_EQ(m.triangleCount(), TubeTriangles(2, 6) + TubeTriangles(1, 6));
  std::string why;
  EXPECT_EQ(EulerCharacteristic(m, &why), 4) << why;
}

TEST(Tessellator, CatalogueMeshesAreValid) {
  for (const char* f : {"fig2_06a_monopodial", "fig2_07b_sympodial", "fig2_08a_ternary",
                        "fig1_24d_bracketed_plant", "fig1_25_bush", "fig1_19_hilbert_3d"}) {
    PlantGeometry g = DrawFile(f);
    TriangleMesh m = Mesh(g, 8);
    EXPECT_GT(m.triangleCount(), 100u) << f;
    EXPECT_EQ(Validate(m, 1e-14f), "") << f;
  }
}

// Splits the mesh into edge-connected components and returns the Euler
// characteristic of each (a vertex shared by two tubes, as where sibling
// branches start at one point, is counted in each).
std::vector<long> ComponentEulerCharacteristics(const TriangleMesh& m) {
  std::map<std::tuple<float, float, float>, uint32_t> weld;
  std::vector<uint32_t> id(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    auto key = std::make_tuple(m.positions[i].x(), m.positions[i].y(), m.positions[i].z());
    id[i] = weld.emplace(key, uint32_t(weld.size())).first->second;
  }
  const size_t nt = m.triangleCount();
  std::vector<size_t> parent(nt);
  for (size_t t = 0; t < nt; ++t) parent[t] = t;
  std::function<size_t(size_t)> find = [&](size_t x) {
    return parent[x] == x ? x : parent[x] = find(parent[x]);
  };
  std::map<std::pair<uint32_t, uint32_t>, size_t> edgeOwner;
  for (size_t t = 0; t < nt; ++t) {
    for (int e = 0; e < 3; ++e) {
      uint32_t a = id[m.indices[3 * t + e]], b = id[m.indices[3 * t + (e + 1) % 3]];
      auto key = std::minmax(a, b);
      auto [it, fresh] = edgeOwner.emplace(key, t);
      if (!fresh) parent[find(t)] = find(it->second);
    }
  }
  std::map<size_t, std::set<uint32_t>> verts;
  std::map<size_t, std::set<std::pair<uint32_t, uint32_t>>> edges;
  std::map<size_t, long> faces;
  for (size_t t = 0; t < nt; ++t) {
    size_t c = find(t);
    ++faces[c];
    for (int e = 0; e < 3; ++e) {
      uint32_t a = id[m.indices[3 * t + e]], b = id[m.indices[3 * t + (e + 1) % 3]];
      verts[c].insert(a);
      edges[c].insert(std::minmax(a, b));
    }
  }
  std::vector<long> chi;
  for (const auto& [c, f] : faces) chi.push_back(long(verts[c].size()) - long(edges[c].size()) + f);
  return chi;
}

TEST(Tessellator, MonopodialTreeTubesAreClosed) {
  PlantGeometry g = DrawFile("fig2_06a_monopodial", 6);
  TriangleMesh m = Mesh(g, 6);
  std::string why;
  EulerCharacteristic(m, &why);
  EXPECT_EQ(why, "") << "closed and consistently oriented";
  auto chi = ComponentEulerCharacteristics(m);
  EXPECT_GT(chi.size(), 10u);
  for (size_t c = 0; c < chi.size(); ++c) EXPECT_EQ(chi[c], 2) << "component " << c;
}

TEST(Tessellator, PlanarChainsDoNotTwist) {
  // A chain turning in the XY plane: the rotation-minimizing frame keeps the
  // binormal on the plane's normal, so the vertex at a quarter turn of every
  // ring sits straight above the axis point.
  PlantGeometry g = Draw("angle: 25\naxiom: F+F+F-F+F\n");
  const int S = 8;
  TriangleMesh m = Mesh(g, S);
  for (int k = 0; k <= 5; ++k) {
    Vec3 axis = k == 0 ? g.segments[0].start : g.segments[size_t(k - 1)].end;
    Vec3f q = m.positions[size_t(k * (S + 1) + S / 4)];
    EXPECT_NEAR(q.x(), axis.x(), 1e-5) << "ring " << k;
    EXPECT_NEAR(q.y(), axis.y(), 1e-5) << "ring " << k;
    EXPECT_NEAR(q.z(), 0.5, 1e-5) << "ring " << k;
  }
}

TEST(Tessellator, RadiusTapersToTheNextInternodeAndVIsWorldLength) {
  PlantGeometry g = Draw("axiom: !(2)F(1)!(1)F(2)\n");
  const int S = 4;
  TriangleMesh m = Mesh(g, S);
  auto ringRadius = [&](int k, const Vec3& axis) {
    return (m.positions[size_t(k * (S + 1))].cast<double>() - axis).norm();
  };
  EXPECT_NEAR(ringRadius(0, Vec3(0, 0, 0)), 1.0, 1e-6);
  EXPECT_NEAR(ringRadius(1, Vec3(0, 1, 0)), 0.5, 1e-6);
  EXPECT_NEAR(ringRadius(2, Vec3(0, 3, 0)), 0.5, 1e-6);
  EXPECT_FLOAT_EQ(m.uvs[size_t(2 * (S + 1))].y(), 3.0f);
  EXPECT_FLOAT_EQ(m.uvs[size_t(S)].x(), 1.0f);  // seam vertex
}

TEST(Tessellator, DetailIsChosenPerPrimitive) {
  PlantGeometry g = Draw("axiom: F[+(90)f(10)F]\n");
  TessellateOptions opt;
  opt.detailFn = [](const Vec3& c, double) { return Detail{c.norm() > 5 ? 4 : 12}; };
  TriangleMesh m;
  ASSERT_TRUE(Tessellate(g, opt, m).ok());
  EXPECT_EQ(m.triangleCount(), TubeTriangles(1, 12) + TubeTriangles(1, 4));
}

TEST(Tessellator, ConcavePolygonsAreEarClipped) {
  // An L-shaped hexagon (concave), area 3.
  std::vector<Vec3> l = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  Vec3 n;
  auto tris = TriangulatePolygon(l, &n);
  ASSERT_EQ(tris.size(), 12u);
  double area = 0;
  for (size_t t = 0; t < tris.size(); t += 3) {
    Vec3 e = (l[tris[t + 1]] - l[tris[t]]).cross(l[tris[t + 2]] - l[tris[t]]);
    EXPECT_GT(e.dot(n), 0) << "triangle " << t / 3 << " faces the other way";
    area += 0.5 * e.norm();
  }
  EXPECT_NEAR(area, 3.0, 1e-12);
  EXPECT_NEAR(n.z(), 1.0, 1e-12);
  // Clockwise input: same area, opposite normal.
  std::reverse(l.begin(), l.end());
  EXPECT_EQ(TriangulatePolygon(l, &n).size(), 12u);
  EXPECT_NEAR(n.z(), -1.0, 1e-12);
}

TEST(Tessellator, DegeneratePolygonsAreSkippedWithAWarning) {
  PlantGeometry g;
  Polygon flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.module = 4;
  g.polygons.push_back(flat);
  TriangleMesh m;
  TessellateStats stats;
  ASSERT_TRUE(Tessellate(g, {}, m, &stats).ok());
  EXPECT_EQ(m.triangleCount(), 0u);
  ASSERT_EQ(stats.warnings.size(), 1u);
  EXPECT_EQ(stats.warnings[0],
            "polygon at module 5 is degenerate, crosses itself or is too complex to triangulate; "
            "skipped");
}

TEST(Tessellator, LeafPolygonsOfTheBush) {
  PlantGeometry g = DrawFile("fig1_25_bush", 3);
  ASSERT_GT(g.polygons.size(), 0u);
  TriangleMesh m = Mesh(g, 6);
  EXPECT_EQ(Validate(m), "");
}

TEST(Tessellator, SpheresAreClosedAndRound) {
  PlantGeometry g = Draw("axiom: f(3)@O(4)\n");
  const int S = 10;
  TriangleMesh m = Mesh(g, S);
  EXPECT_EQ(m.triangleCount(), size_t(2 * S * (S / 2 - 1)));
  for (const Vec3f& p : m.positions) EXPECT_NEAR((p - Vec3f(0, 3, 0)).norm(), 2.0f, 1e-5f);
  std::string why;
  EXPECT_EQ(EulerCharacteristic(m, &why), 2) << why;
  EXPECT_EQ(Validate(m), "");
}

TEST(Tessellator, UnknownSurfaceIsAnError) {
  PlantGeometry g = Draw("axiom: F~nope\n");
  TriangleMesh m;
  Status s = Tessellate(g, {}, m);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, "unknown surface 'nope'");
  EXPECT_EQ(m.triangleCount(), 0u);
}

}  // namespace
}  // namespace sylva::mesh

#include "mesh/obj_reader.h"

namespace sylva::mesh {
namespace {

TEST(ObjReader, ReadsPolygonsWithAllIndexForms) {
  auto m = ParseObj(
      "# a unit square and a triangle\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
      "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
      "f -4//1 -3//1 -1//1\n",
      "sq.obj");
  ASSERT_TRUE(m.ok()) << m.error().Format();
  EXPECT_EQ(m->triangleCount(), 3u);
  EXPECT_EQ(Validate(*m), "");
  EXPECT_EQ(m->uvs[2], Vec2f(1, 1));
}

TEST(ObjReader, ComputesMissingNormals) {
  auto m = ParseObj("v 0 0 0\nv 0 0 1\nv 1 0 0\nf 1 2 3\n", "n.obj");
  ASSERT_TRUE(m.ok());
  EXPECT_NEAR(m->normals[0].y(), 1.0f, 1e-6f);
}

TEST(ObjReader, ErrorsNameLineAndColumn) {
  auto bad = ParseObj("v 0 0 0\nv 1 x 0\n", "bad.obj");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().loc.line, 2);
  EXPECT_EQ(bad.error().loc.column, 5);  // the x
  auto range = ParseObj("v 0 0 0\nv 1 0 0\nf 1 2 7\n", "r.obj");
  ASSERT_FALSE(range.ok());
  EXPECT_EQ(range.error().message, "vertex index 7 out of range");
  EXPECT_EQ(range.error().loc.column, 7);
  EXPECT_FALSE(ParseObj("# nothing\n", "e.obj").ok());
}

TEST(ObjReader, DevicesAndDirectoriesAreErrorsNotHangsOrCrashes) {
  // ReadFile's checks: /dev/zero used to end in bad_alloc.
  for (const char* p : {"/dev/zero", "/dev/null", "/tmp"}) {
    auto m = ReadObj(p);
    ASSERT_FALSE(m.ok()) << p;
    EXPECT_EQ(m.error().loc.file, p);
    EXPECT_EQ(m.error().message.rfind("is ", 0), 0u) << m.error().message;
  }
}

TEST(ObjReader, BundledSurfacesAreValidMeshes) {
  for (const char* name : {"leaf", "petal", "flower"}) {
    auto m = ReadObj(std::string(SYLVA_SOURCE_DIR) + "/grammars/surfaces/" + name + ".obj");
    ASSERT_TRUE(m.ok()) << name << ": " << m.error().Format();
    EXPECT_EQ(Validate(*m), "") << name;
    EXPECT_GT(m->triangleCount(), 4u) << name;
  }
}

TEST(Tessellator, SurfacesArePlacedByTheTurtleFrameAndScaled) {
  TriangleMesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  tri.uvs = {{0, 0}, {1, 0}, {0, 1}};
  tri.indices = {0, 1, 2};
  tri.material = {0};
  std::unordered_map<std::string, TriangleMesh> lib{{"t", tri}};
  PlantGeometry g = Draw("axiom: F+'~t(2)\n");
  TessellateOptions opt;
  opt.surfaces = &lib;
  TriangleMesh m;
  ASSERT_TRUE(Tessellate(g, opt, m).ok());
  // After F+ the turtle is at (0,1,0) with H = (-1,0,0), L = (0,-1,0), U = (0,0,-1):
  // local x -> L, y -> H, z -> U, scaled by 2.
  const size_t n = m.vertexCount();
  EXPECT_LT((m.positions[n - 3] - Vec3f(0, 1, 0)).norm(), 1e-6f);
  EXPECT_LT((m.positions[n - 2] - Vec3f(0, -1, 0)).norm(), 1e-6f);
  EXPECT_LT((m.positions[n - 1] - Vec3f(-2, 1, 0)).norm(), 1e-6f);
  EXPECT_LT((m.normals[n - 1] - Vec3f(0, 0, -1)).norm(), 1e-6f);
  EXPECT_EQ(m.material.back(), 1);
}

}  // namespace
}  // namespace sylva::mesh

namespace sylva::mesh {
namespace {

TEST(Export, AMeshWithANonFiniteNumberIsNeverWritten) {
  TriangleMesh m;
  m.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  m.normals = {Vec3f(0, 0, 1), Vec3f(0, std::nanf(""), 1), Vec3f(0, 0, 1)};  // NaN in y
  m.uvs = {Vec2f(0, 0), Vec2f(1, 0), Vec2f(0, 1)};
  m.indices = {0, 1, 2};
  m.material = {0};
  EXPECT_EQ(FindNonFinite(m), "the normal of vertex 1 is not finite");
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("sylva_nan_" + std::to_string(::getpid()) + ".glb"))
                               .string();
  Status s = WriteMesh(m, DefaultPalette(), path);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("not finite"), std::string::npos) << s.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));
  m.normals[1] = Vec3f(0, 0, 1);
  m.positions[2].z() = std::numeric_limits<float>::infinity();
  EXPECT_EQ(FindNonFinite(m), "the position of vertex 2 is not finite");
}

}  // namespace
}  // namespace sylva::mesh

namespace sylva::mesh {
namespace {

// Materials are named by their colour, so one name means one definition in
// every .mtl, and an .obj never points at a material its .mtl lacks.
TEST(Export, ObjMaterialsAreNamedByColourAndAllDefinedInTheMtl) {
  auto p =
      testing::PlantFromText("palette: #808080 #ff0000\naxiom: F'F\n", -1, plant::Stage::kMesh);
  ASSERT_TRUE(p);
  const auto dir =
      std::filesystem::temp_directory_path() / ("sylva_mtl_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string obj = (dir / "two.obj").string();
  ASSERT_TRUE(WriteMesh(p->mesh, p->palette, obj).ok());
  const std::string objText = *ReadFile(obj), mtlText = *ReadFile((dir / "two.mtl").string());
  size_t uses = 0;
  for (size_t at = objText.find("usemtl "); at != std::string::npos;
       at = objText.find("usemtl ", at + 1)) {
    const std::string name = objText.substr(at + 7, objText.find('\n', at) - at - 7);
    EXPECT_NE(mtlText.find("newmtl " + name + "\n"), std::string::npos) << name << " not in:\n"
                                                                        << mtlText;
    ++uses;
  }
  EXPECT_EQ(uses, 2u);
  EXPECT_NE(mtlText.find("newmtl kd_0.5019608_0.5019608_0.5019608\n"), std::string::npos)
      << mtlText;
  // A second export leaves only its own materials.
  auto grey = testing::PlantFromText("palette: #808080\naxiom: F\n", -1, plant::Stage::kMesh);
  ASSERT_TRUE(grey);
  ASSERT_TRUE(WriteMesh(grey->mesh, grey->palette, obj).ok());
  const std::string after = *ReadFile((dir / "two.mtl").string());
  EXPECT_EQ(after.find("kd_0.99999994"), std::string::npos) << after;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sylva::mesh
