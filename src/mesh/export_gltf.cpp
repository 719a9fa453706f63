// glTF 2.0 through tinygltf (Debian libtinygltf-dev): one buffer holding
// positions, normals, UVs and the indices grouped by material; one mesh with
// one primitive per material; PBR materials from the palette, rough and
// non-metallic, double-sided (leaves are single polygons).
//
// tinygltf builds and serialises the document. For .glb, Sylva writes the
// container itself (glTF 2.0 spec, section 4.4: a 12-byte header, a JSON
// chunk, a BIN chunk) and streams the BIN chunk straight from the mesh
// arrays: a million-segment tree makes a 1 GB buffer, which must not be
// copied three times on its way to the disk. For .gltf the buffer is
// embedded as a base64 data URI, so the file stands alone.
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <sstream>

#include "core/atomic_file.h"
#include "mesh/color.h"
#include "mesh/export.h"
#include "mesh/glb.h"
#include "mesh/tessellator.h"

namespace sylva::mesh {
namespace {

// What the JSON says about the buffer: vertex count, position bounds, and
// per material group its triangles and smallest and largest index.
struct Summary {
  size_t vertices = 0;
  Vec3f lo = Vec3f::Zero(), hi = Vec3f::Zero();
  std::vector<uint16_t> materials;
  std::vector<size_t> triangles;
  std::vector<uint32_t> indexLo, indexHi;
};

Summary Summarize(const TriangleMesh& m, const MaterialGroups& groups) {
  Summary s;
  s.vertices = m.vertexCount();
  if (s.vertices > 0) {
    s.lo = s.hi = m.positions[0];
    for (const Vec3f& p : m.positions) {
      s.lo = s.lo.cwiseMin(p);
      s.hi = s.hi.cwiseMax(p);
    }
  }
  s.materials = groups.materials;
  for (size_t k = 0; k < groups.materials.size(); ++k) {
    uint32_t lo = UINT32_MAX, hi = 0;
    for (uint32_t o = groups.starts[k]; o < groups.starts[k + 1]; ++o) {
      for (int e = 0; e < 3; ++e) {
        const uint32_t i = m.indices[3 * groups.order[o] + e];
        lo = std::min(lo, i);
        hi = std::max(hi, i);
      }
    }
    s.triangles.push_back(groups.starts[k + 1] - groups.starts[k]);
    s.indexLo.push_back(lo);
    s.indexHi.push_back(hi);
  }
  return s;
}

// Byte layout of the single buffer: attributes, then one index block per
// material, each 4-byte aligned (all parts are 4-byte multiples already).
struct Layout {
  size_t positions = 0, normals = 0, uvs = 0;
  std::vector<size_t> indexOffset;  // per material group
  size_t total = 0;
};

Layout MakeLayout(const Summary& s) {
  Layout l;
  const size_t nv = s.vertices;
  l.positions = 0;
  l.normals = nv * 12;
  l.uvs = nv * 24;
  size_t at = nv * 32;
  for (size_t k = 0; k < s.materials.size(); ++k) {
    l.indexOffset.push_back(at);
    at += s.triangles[k] * 12;
  }
  l.total = at;
  return l;
}

tinygltf::Model BuildModel(const Summary& sum, const Palette& palette, const Layout& layout) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "Sylva";
  const size_t nv = sum.vertices;
  auto view = [&](size_t offset, size_t bytes, int target) {
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = offset;
    v.byteLength = bytes;
    v.target = target;
    model.bufferViews.push_back(v);
    return int(model.bufferViews.size() - 1);
  };
  auto accessor = [&](int bufferView, int componentType, size_t count, int type,
                      std::vector<double> mn = {}, std::vector<double> mx = {}) {
    tinygltf::Accessor a;
    a.bufferView = bufferView;
    a.componentType = componentType;
    a.count = count;
    a.type = type;
    a.minValues = std::move(mn);
    a.maxValues = std::move(mx);
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  };
  tinygltf::Primitive base;
  base.mode = TINYGLTF_MODE_TRIANGLES;
  if (nv > 0) {
    const Vec3f lo = sum.lo, hi = sum.hi;
    base.attributes["POSITION"] =
        accessor(view(layout.positions, nv * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                 TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3, {lo.x(), lo.y(), lo.z()},
                 {hi.x(), hi.y(), hi.z()});
    base.attributes["NORMAL"] =
        accessor(view(layout.normals, nv * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                 TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3);
    base.attributes["TEXCOORD_0"] = accessor(view(layout.uvs, nv * 8, TINYGLTF_TARGET_ARRAY_BUFFER),
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC2);
  }
  tinygltf::Mesh mesh;
  mesh.name = "plant";
  for (size_t k = 0; k < sum.materials.size(); ++k) {
    const uint32_t lo = sum.indexLo[k], hi = sum.indexHi[k];
    const size_t count = sum.triangles[k] * 3;
    tinygltf::Primitive prim = base;
    prim.indices =
        accessor(view(layout.indexOffset[k], count * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, count, TINYGLTF_TYPE_SCALAR, {double(lo)},
                 {double(hi)});
    tinygltf::Material mat;
    const uint16_t ci = sum.materials[k];
    mat.name = "color" + std::to_string(ci);
    const Vec3f c = palette.empty() ? Srgb(0.8f, 0.8f, 0.8f)
                                    : palette[ci % palette.size()];  // linear, as glTF wants
    mat.pbrMetallicRoughness.baseColorFactor = {c.x(), c.y(), c.z(), 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.9;
    mat.doubleSided = true;
    model.materials.push_back(mat);
    prim.material = int(model.materials.size() - 1);
    mesh.primitives.push_back(prim);
  }
  if (!mesh.primitives.empty()) {
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.mesh = 0;
    node.name = "plant";
    model.nodes.push_back(node);
  }
  tinygltf::Scene scene;
  scene.name = "Sylva";
  if (!model.nodes.empty()) scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  return model;
}

// Calls sink(bytes, size) with the buffer's content in order, in pieces.
template <typename Sink>
Status EmitBuffer(const TriangleMesh& m, const MaterialGroups& groups, Sink&& sink) {
  const size_t nv = m.vertexCount();
  if (Status s = sink(m.positions.data(), nv * 12); !s.ok()) return s;
  if (Status s = sink(m.normals.data(), nv * 12); !s.ok()) return s;
  if (Status s = sink(m.uvs.data(), nv * 8); !s.ok()) return s;
  std::vector<uint32_t> block;
  block.reserve(3 * 65536);
  for (size_t k = 0; k < groups.materials.size(); ++k) {
    for (uint32_t o = groups.starts[k]; o < groups.starts[k + 1]; ++o) {
      const uint32_t* t = &m.indices[3 * size_t(groups.order[o])];
      block.insert(block.end(), t, t + 3);
      if (block.size() >= 3 * 65536) {
        if (Status s = sink(block.data(), block.size() * 4); !s.ok()) return s;
        block.clear();
      }
    }
  }
  if (!block.empty()) return sink(block.data(), block.size() * 4);
  return {};
}

Status SerialisationFailed(const std::string& path) {
  Diagnostic d;
  d.kind = ErrorKind::kRuntime;
  d.loc.file = path;
  d.message = "glTF serialisation failed";
  return d;
}

const char* const kTooLarge =
    "mesh too large for a .glb file (over 4 GiB); use fewer sides or steps";

// The GLB's JSON chunk: tinygltf's document with the buffer declared by
// length only (the GLB buffer has no uri); nullopt if serialisation fails.
std::optional<std::string> GlbJson(tinygltf::Model model, size_t bufferBytes) {
  if (bufferBytes > 0) {
    tinygltf::Buffer placeholder;
    placeholder.uri = "bin";  // replaced below
    model.buffers.push_back(placeholder);
  }
  tinygltf::TinyGLTF writer;
  std::ostringstream stream;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, false)) return std::nullopt;
  nlohmann::json doc = nlohmann::json::parse(stream.str(), nullptr, false);
  if (doc.is_discarded()) return std::nullopt;
  if (bufferBytes > 0) doc["buffers"] = nlohmann::json::array({{{"byteLength", bufferBytes}}});
  return doc.dump();
}

}  // namespace

Status WriteGltf(const TriangleMesh& m, const Palette& palette, const std::string& path,
                 bool binary) {
  static_assert(sizeof(Vec3f) == 12 && sizeof(Vec2f) == 8);
  const MaterialGroups groups = GroupByMaterial(m);
  const Summary summary = Summarize(m, groups);
  const Layout layout = MakeLayout(summary);
  tinygltf::Model model = BuildModel(summary, palette, layout);
  tinygltf::TinyGLTF writer;
  AtomicFile f;

  if (!binary) {
    if (layout.total > 0) {
      tinygltf::Buffer buffer;
      buffer.data.reserve(layout.total);
      (void)EmitBuffer(m, groups, [&](const void* p, size_t n) -> Status {
        const auto* b = static_cast<const unsigned char*>(p);
        buffer.data.insert(buffer.data.end(), b, b + n);
        return {};
      });
      model.buffers.push_back(std::move(buffer));
    }
    std::ostringstream stream;
    if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/true, false))
      return SerialisationFailed(path);
    if (Status s = f.Open(path); !s.ok()) return s;
    if (Status s = f.Write(stream.str()); !s.ok()) return s;
    return f.Commit();
  }

  // GLB: the JSON from tinygltf, with the buffer declared by length only.
  auto json = GlbJson(model, layout.total);
  if (!json) return SerialisationFailed(path);
  return WriteGlb(
      path, std::move(*json), layout.total,
      [&](const ByteSink& sink) { return EmitBuffer(m, groups, sink); }, kTooLarge);
}

// The streamed .glb: the file is laid out as soon as the counts are known
// (MeshStream::begin): header, a JSON chunk with room reserved, then the
// BIN chunk, whose parts each piece writes at their offsets (pwrite: the
// kernel's page cache holds them, not this process). The JSON, which
// needs the bounds, is written last into its room, padded with spaces.
Status WriteGlbStreamed(const Palette& palette, const std::string& path,
                        const std::function<Status(const MeshStream&)>& tessellate,
                        MeshCounts* counts) {
  // A FIFO or device cannot seek: the pieces are gathered, then written.
  struct stat st;
  const bool gather = stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode);
  TriangleMesh whole;
  AtomicFile f;
  if (!gather) {
    if (Status s = f.Open(path); !s.ok()) return s;
  }
  auto ioError = [&](const char* what) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.loc.file = path;
    d.message = std::string(what) + ": " + std::strerror(errno);
    return Status(d);
  };
  const int fd = gather ? -1 : fileno(f.handle());
  auto writeAt = [&](const void* data, size_t bytes, size_t offset) -> Status {
    const char* p = static_cast<const char*>(data);
    while (bytes > 0) {
      const ssize_t n = pwrite(fd, p, bytes, off_t(offset));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return ioError("write failed");
      p += n;
      bytes -= size_t(n);
      offset += size_t(n);
    }
    return {};
  };

  Summary sum;
  Layout layout;
  std::vector<int> group;                      // material -> its group, or -1
  std::vector<size_t> cursor;                  // per group: triangles written so far
  std::vector<std::vector<uint32_t>> scatter;  // per group: this piece's indices
  size_t binAt = 0, jsonRoom = 0, triangles = 0;
  bool anyVertex = false;
  MeshStream stream;
  stream.begin = [&](size_t vertices, const std::vector<size_t>& perMaterial) -> Status {
    sum.vertices = vertices;
    group.assign(perMaterial.size(), -1);
    for (size_t m = 0; m < perMaterial.size(); ++m) {
      if (!perMaterial[m]) continue;
      group[m] = int(sum.materials.size());
      sum.materials.push_back(uint16_t(m));
      sum.triangles.push_back(perMaterial[m]);
      sum.indexLo.push_back(UINT32_MAX);
      sum.indexHi.push_back(0);
      triangles += perMaterial[m];
    }
    cursor.assign(sum.materials.size(), 0);
    scatter.resize(sum.materials.size());
    layout = MakeLayout(sum);
    if (gather) return {};
    // Room for the JSON: the document with these counts, plus 32 bytes for
    // each bound (a double prints in at most 25 characters).
    auto json = GlbJson(BuildModel(sum, palette, layout), layout.total);
    if (!json) return SerialisationFailed(path);
    jsonRoom = (json->size() + 32 * (6 + 2 * sum.materials.size()) + 3) / 4 * 4;
    binAt = 12 + 8 + jsonRoom + 8;
    if (binAt + layout.total > 0xFFFFFFFFull) {
      Diagnostic d;
      d.kind = ErrorKind::kRuntime;
      d.loc.file = path;
      d.message = kTooLarge;
      return d;
    }
    return {};
  };
  stream.piece = [&](const TriangleMesh& piece, size_t first) -> Status {
    if (std::string bad = FindNonFinite(piece); !bad.empty()) {
      Diagnostic d;
      d.loc.file = path;
      d.message =
          "not written: " + bad + " (of the piece from vertex " + std::to_string(first) + ")";
      return d;
    }
    if (gather) {
      // Not Append: the piece's indices are already the whole mesh's.
      auto add = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
      add(whole.positions, piece.positions);
      add(whole.normals, piece.normals);
      add(whole.uvs, piece.uvs);
      add(whole.indices, piece.indices);
      add(whole.material, piece.material);
      return {};
    }
    const size_t nv = piece.vertexCount();
    for (const Vec3f& p : piece.positions) {
      if (!anyVertex) sum.lo = sum.hi = p;
      anyVertex = true;
      sum.lo = sum.lo.cwiseMin(p);
      sum.hi = sum.hi.cwiseMax(p);
    }
    if (Status s = writeAt(piece.positions.data(), nv * 12, binAt + layout.positions + 12 * first);
        !s.ok())
      return s;
    if (Status s = writeAt(piece.normals.data(), nv * 12, binAt + layout.normals + 12 * first);
        !s.ok())
      return s;
    if (Status s = writeAt(piece.uvs.data(), nv * 8, binAt + layout.uvs + 8 * first); !s.ok())
      return s;
    for (auto& v : scatter) v.clear();
    for (size_t t = 0; t < piece.triangleCount(); ++t) {
      const int k = group[piece.material[t]];
      const uint32_t* tri = &piece.indices[3 * t];
      scatter[size_t(k)].insert(scatter[size_t(k)].end(), tri, tri + 3);
      sum.indexLo[size_t(k)] = std::min({sum.indexLo[size_t(k)], tri[0], tri[1], tri[2]});
      sum.indexHi[size_t(k)] = std::max({sum.indexHi[size_t(k)], tri[0], tri[1], tri[2]});
    }
    for (size_t k = 0; k < scatter.size(); ++k) {
      if (scatter[k].empty()) continue;
      const size_t at = binAt + layout.indexOffset[k] + 12 * cursor[k];
      if (Status s = writeAt(scatter[k].data(), scatter[k].size() * 4, at); !s.ok()) return s;
      cursor[k] += scatter[k].size() / 3;
    }
    return {};
  };
  if (Status s = tessellate(stream); !s.ok()) return s;
  if (counts) *counts = {sum.vertices, triangles};
  if (gather) return WriteGltf(whole, palette, path, true);
  for (size_t k = 0; k < cursor.size(); ++k) SYLVA_ASSERT(cursor[k] == sum.triangles[k]);
  auto json = GlbJson(BuildModel(sum, palette, layout), layout.total);
  if (!json) return SerialisationFailed(path);
  SYLVA_ASSERT(json->size() <= jsonRoom);
  json->resize(jsonRoom, ' ');
  const size_t length = layout.total > 0 ? binAt + layout.total : 20 + jsonRoom;
  const uint32_t header[5] = {0x46546C67u, 2, uint32_t(length), uint32_t(jsonRoom),
                              0x4E4F534Au};  // "glTF", version, length, JSON chunk
  if (Status s = writeAt(header, sizeof header, 0); !s.ok()) return s;
  if (Status s = writeAt(json->data(), jsonRoom, 20); !s.ok()) return s;
  if (layout.total > 0) {
    const uint32_t bin[2] = {uint32_t(layout.total), 0x004E4942u};  // "BIN\0"
    if (Status s = writeAt(bin, sizeof bin, 20 + jsonRoom); !s.ok()) return s;
  }
  return f.Commit();
}

}  // namespace sylva::mesh
