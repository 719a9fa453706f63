// The streamed tessellation (MeshStream) and the streamed .glb writer
// (WriteGlbStreamed): the pieces are the whole mesh, and the file is
// WriteGltf's but for the JSON chunk's padding.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "mesh/export.h"
#include "mesh/tessellator.h"
#include "mesh/view_test_util.h"
#include "plant/plant_test_util.h"

namespace sylva::mesh {
namespace {

PlantGeometry DrawFile(const std::string& name, int steps) {
  auto p = testing::PlantFromFile("abop/" + name + ".lsys", steps);
  return p ? std::move(p->geometry) : PlantGeometry{};
}

// A perspective view (OpenGL conventions) from eye toward target.
ScreenView ViewFrom(const Vec3& eye, const Vec3& target, bool coverage) {
  ScreenView view;
  view.width = 960;
  view.height = 540;
  view.viewProjection = testing::LookAtPerspective(eye, target, 35, 960.0 / 540);
  view.coverage = coverage;
  return view;
}

// The pieces a stream receives, appended, with what `begin` announced.
struct Gathered {
  TriangleMesh mesh;
  size_t announcedVertices = 0;
  std::vector<size_t> announcedPerMaterial;
  size_t pieces = 0;
  bool firstVertexRight = true;
};

Gathered Stream(const PlantGeometry& g, TessellateOptions opt, size_t pieceVertices) {
  Gathered out;
  MeshStream stream;
  stream.pieceVertices = pieceVertices;
  stream.begin = [&](size_t v, const std::vector<size_t>& perMaterial) {
    out.announcedVertices = v;
    out.announcedPerMaterial = perMaterial;
    return Status{};
  };
  stream.piece = [&](const TriangleMesh& piece, size_t first) {
    out.firstVertexRight = out.firstVertexRight && first == out.mesh.vertexCount();
    // Not Append, which offsets indices: a piece's are the whole mesh's.
    auto add = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
    add(out.mesh.positions, piece.positions);
    add(out.mesh.normals, piece.normals);
    add(out.mesh.uvs, piece.uvs);
    add(out.mesh.indices, piece.indices);
    add(out.mesh.material, piece.material);
    add(out.mesh.coverage, piece.coverage);
    ++out.pieces;
    return Status{};
  };
  opt.stream = &stream;
  TriangleMesh unused;
  EXPECT_TRUE(Tessellate(g, opt, unused).ok());
  EXPECT_EQ(unused.vertexCount(), 0u);
  return out;
}

void ExpectSameMesh(const TriangleMesh& a, const TriangleMesh& b, const std::string& what) {
  ASSERT_EQ(a.vertexCount(), b.vertexCount()) << what;
  ASSERT_EQ(a.triangleCount(), b.triangleCount()) << what;
  EXPECT_EQ(a.coverage.size(), b.coverage.size()) << what;
  EXPECT_TRUE(a.indices == b.indices) << what;
  EXPECT_TRUE(a.material == b.material) << what;
  EXPECT_TRUE(a.coverage == b.coverage) << what;
  size_t differ = 0;
  for (size_t i = 0; i < a.vertexCount(); ++i) {
    differ +=
        !(a.positions[i] == b.positions[i] && a.normals[i] == b.normals[i] && a.uvs[i] == b.uvs[i]);
  }
  EXPECT_EQ(differ, 0u) << what << ": vertices that differ";
}

// Uniform sides, a screen view with coverage lines and culling, leaves
// (polygons) and spheres: the pieces, appended, are Tessellate's mesh,
// whatever the piece size, and `begin` announced its exact counts.
TEST(MeshStream, PiecesAppendedAreTheWholeMesh) {
  struct Case {
    std::string name;
    PlantGeometry g;
    TessellateOptions opt;
  };
  std::vector<Case> cases;
  cases.push_back({"2.6a uniform 16", DrawFile("fig2_06a_monopodial", 9), {}});
  cases.back().opt.detail.sides = 16;
  cases.push_back({"bush (leaves)", DrawFile("fig1_25_bush", 3), {}});
  auto spheres = testing::PlantFromText("axiom: F(1)@O(0.3)[+F(1)@O(0.2)]F(1)@O(0.25)\n", -1);
  ASSERT_TRUE(spheres);
  cases.push_back({"spheres", std::move(spheres->geometry), {}});
  cases.push_back({"2.6a screen view", DrawFile("fig2_06a_monopodial", 9), {}});
  cases.back().opt.view = ViewFrom(Vec3(3, 4, 6), Vec3(0, 3, 0), true);
  cases.push_back({"bush screen view", DrawFile("fig1_25_bush", 3), {}});
  cases.back().opt.view = ViewFrom(Vec3(20, 10, 40), Vec3(0, 3, 0), true);
  for (Case& c : cases) {
    TriangleMesh whole;
    ASSERT_TRUE(Tessellate(c.g, c.opt, whole).ok()) << c.name;
    ASSERT_GT(whole.triangleCount(), 0u) << c.name;
    std::vector<size_t> perMaterial;
    for (uint16_t m : whole.material) {
      if (m >= perMaterial.size()) perMaterial.resize(m + 1, 0);
      ++perMaterial[m];
    }
    for (size_t pieceVertices : {size_t(0), size_t(100), size_t(1) << 20}) {
      const std::string what = c.name + ", pieces of " + std::to_string(pieceVertices);
      Gathered got = Stream(c.g, c.opt, pieceVertices);
      ExpectSameMesh(got.mesh, whole, what);
      EXPECT_EQ(got.announcedVertices, whole.vertexCount()) << what;
      EXPECT_TRUE(got.announcedPerMaterial == perMaterial) << what;
      EXPECT_TRUE(got.firstVertexRight) << what;
      if (pieceVertices == 100 && whole.vertexCount() > 1000) EXPECT_GT(got.pieces, 2u) << what;
    }
  }
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("sylva_stream_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

uint32_t U32(const std::string& s, size_t at) {
  uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

// The streamed .glb: the header's length is the file's, the BIN chunk is
// byte for byte WriteGltf's, and the JSON chunk is WriteGltf's text
// followed by spaces only.
TEST(GlbStreamed, BinIsWriteGltfsAndTheJsonDiffersOnlyInPadding) {
  const PlantGeometry g = DrawFile("fig1_25_bush", 3);
  TessellateOptions opt;
  opt.detail.sides = 7;
  TriangleMesh whole;
  ASSERT_TRUE(Tessellate(g, opt, whole).ok());
  const std::string a = TempPath("whole.glb"), b = TempPath("streamed.glb");
  ASSERT_TRUE(WriteGltf(whole, DefaultPalette(), a, true).ok());
  MeshCounts counts;
  Status s = WriteGlbStreamed(
      DefaultPalette(), b,
      [&](const MeshStream& stream) {
        MeshStream small = stream;
        small.pieceVertices = 500;  // many pieces
        TessellateOptions o = opt;
        o.stream = &small;
        TriangleMesh unused;
        return Tessellate(g, o, unused);
      },
      &counts);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(counts.vertices, whole.vertexCount());
  EXPECT_EQ(counts.triangles, whole.triangleCount());
  const std::string x = ReadAll(a), y = ReadAll(b);
  std::filesystem::remove(a);
  std::filesystem::remove(b);
  ASSERT_GT(x.size(), 28u);
  ASSERT_GT(y.size(), 28u);
  EXPECT_EQ(U32(y, 8), y.size()) << "the header's length";
  EXPECT_EQ(y.substr(0, 8), x.substr(0, 8));
  const uint32_t jx = U32(x, 12), jy = U32(y, 12);
  EXPECT_EQ(jy % 4, 0u);
  ASSERT_GE(jy, jx);
  const std::string jsonX = x.substr(20, jx), jsonY = y.substr(20, jy);
  EXPECT_EQ(jsonY.substr(0, jx), jsonX);
  EXPECT_EQ(jsonY.find_first_not_of(' ', jx), std::string::npos) << "padding is spaces only";
  EXPECT_EQ(x.substr(20 + jx), y.substr(20 + jy)) << "the BIN chunk (with its header)";
}

// A piece with a NaN (in z) stops the write: an error, and no file left.
TEST(GlbStreamed, ANonFinitePieceLeavesNoFile) {
  const std::string path = TempPath("nan.glb");
  Status s = WriteGlbStreamed(DefaultPalette(), path, [](const MeshStream& stream) {
    TriangleMesh m;
    m.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, std::nanf(""))};
    m.normals.assign(3, Vec3f(0, 0, 1));
    m.uvs.assign(3, Vec2f(0, 0));
    m.indices = {0, 1, 2};
    m.material = {0};
    if (Status s = stream.begin(3, {1}); !s.ok()) return s;
    return stream.piece(m, 0);
  });
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("not finite"), std::string::npos) << s.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));
}

// A FIFO cannot seek: the pieces are gathered and the reader gets exactly
// what WriteGltf writes of the whole mesh.
TEST(GlbStreamed, AFifoGetsWriteGltfsFile) {
  const PlantGeometry g = DrawFile("fig2_06a_monopodial", 5);
  TessellateOptions opt;
  opt.detail.sides = 5;
  TriangleMesh whole;
  ASSERT_TRUE(Tessellate(g, opt, whole).ok());
  const std::string file = TempPath("fifo_ref.glb"), fifo = TempPath("fifo");
  ASSERT_TRUE(WriteGltf(whole, DefaultPalette(), file, true).ok());
  const std::string expected = ReadAll(file);
  std::filesystem::remove(file);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = ReadAll(fifo); });
  MeshCounts counts;
  Status s = WriteGlbStreamed(
      DefaultPalette(), fifo,
      [&](const MeshStream& stream) {
        MeshStream small = stream;
        small.pieceVertices = 300;
        TessellateOptions o = opt;
        o.stream = &small;
        TriangleMesh unused;
        return Tessellate(g, o, unused);
      },
      &counts);
  reader.join();
  std::filesystem::remove(fifo);
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(counts.triangles, whole.triangleCount());
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
}

}  // namespace
}  // namespace sylva::mesh
