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

#include <cstring>
#include <sstream>

#include "core/atomic_file.h"
#include "mesh/color.h"
#include "mesh/export.h"
#include "mesh/glb.h"

namespace sylva::mesh {
namespace {

// Byte layout of the single buffer: attributes, then one index block per
// material, each 4-byte aligned (all parts are 4-byte multiples already).
struct Layout {
  size_t positions = 0, normals = 0, uvs = 0;
  std::vector<size_t> indexOffset;  // per material group
  size_t total = 0;
};

Layout MakeLayout(const TriangleMesh& m, const MaterialGroups& groups) {
  Layout l;
  const size_t nv = m.vertexCount();
  l.positions = 0;
  l.normals = nv * 12;
  l.uvs = nv * 24;
  size_t at = nv * 32;
  for (size_t k = 0; k < groups.materials.size(); ++k) {
    l.indexOffset.push_back(at);
    at += size_t(groups.starts[k + 1] - groups.starts[k]) * 12;
  }
  l.total = at;
  return l;
}

tinygltf::Model BuildModel(const TriangleMesh& m, const Palette& palette,
                           const MaterialGroups& groups, const Layout& layout) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "Sylva";
  const size_t nv = m.vertexCount();
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
    Vec3f lo = m.positions[0], hi = m.positions[0];
    for (const Vec3f& p : m.positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
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
  for (size_t k = 0; k < groups.materials.size(); ++k) {
    uint32_t lo = UINT32_MAX, hi = 0;
    for (uint32_t o = groups.starts[k]; o < groups.starts[k + 1]; ++o) {
      for (int e = 0; e < 3; ++e) {
        const uint32_t i = m.indices[3 * groups.order[o] + e];
        lo = std::min(lo, i);
        hi = std::max(hi, i);
      }
    }
    const size_t count = size_t(groups.starts[k + 1] - groups.starts[k]) * 3;
    tinygltf::Primitive prim = base;
    prim.indices =
        accessor(view(layout.indexOffset[k], count * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, count, TINYGLTF_TYPE_SCALAR, {double(lo)},
                 {double(hi)});
    tinygltf::Material mat;
    const uint16_t ci = groups.materials[k];
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

}  // namespace

Status WriteGltf(const TriangleMesh& m, const Palette& palette, const std::string& path,
                 bool binary) {
  static_assert(sizeof(Vec3f) == 12 && sizeof(Vec2f) == 8);
  const MaterialGroups groups = GroupByMaterial(m);
  const Layout layout = MakeLayout(m, groups);
  tinygltf::Model model = BuildModel(m, palette, groups, layout);
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
  if (layout.total > 0) {
    tinygltf::Buffer placeholder;
    placeholder.uri = "bin";  // replaced below: the GLB buffer has no uri
    model.buffers.push_back(placeholder);
  }
  std::ostringstream stream;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, false))
    return SerialisationFailed(path);
  nlohmann::json doc = nlohmann::json::parse(stream.str(), nullptr, false);
  if (doc.is_discarded()) return SerialisationFailed(path);
  if (layout.total > 0) doc["buffers"] = nlohmann::json::array({{{"byteLength", layout.total}}});
  return WriteGlb(
      path, doc.dump(), layout.total,
      [&](const ByteSink& sink) { return EmitBuffer(m, groups, sink); },
      "mesh too large for a .glb file (over 4 GiB); use fewer sides or steps");
}

}  // namespace sylva::mesh
