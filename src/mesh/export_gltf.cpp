// glTF 2.0 through tinygltf (Debian libtinygltf-dev): one buffer holding
// positions, normals, UVs and the indices grouped by material; one mesh with
// one primitive per material; PBR materials from the palette, rough and
// non-metallic, double-sided (leaves are single polygons).
#include <tiny_gltf.h>

#include <cstring>
#include <sstream>

#include "core/atomic_file.h"
#include "mesh/export.h"

namespace sylva::mesh {

Status WriteGltf(const TriangleMesh& m, const Palette& palette, const std::string& path,
                 bool binary) {
  const MaterialGroups groups = GroupByMaterial(m);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "Sylva";

  const size_t nv = m.vertexCount();
  tinygltf::Buffer buffer;
  auto append = [&](const void* p, size_t bytes) {
    const size_t at = buffer.data.size();
    buffer.data.resize(at + bytes);
    if (bytes) std::memcpy(buffer.data.data() + at, p, bytes);
    while (buffer.data.size() % 4) buffer.data.push_back(0);
    return at;
  };
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
    const size_t pos = append(m.positions.data(), nv * 12);
    const size_t nor = append(m.normals.data(), nv * 12);
    const size_t uv = append(m.uvs.data(), nv * 8);
    base.attributes["POSITION"] =
        accessor(view(pos, nv * 12, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                 nv, TINYGLTF_TYPE_VEC3, {lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()});
    base.attributes["NORMAL"] = accessor(view(nor, nv * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                                         TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC3);
    base.attributes["TEXCOORD_0"] = accessor(view(uv, nv * 8, TINYGLTF_TARGET_ARRAY_BUFFER),
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC2);
  }
  tinygltf::Mesh mesh;
  mesh.name = "plant";
  std::vector<uint32_t> idx;
  for (size_t k = 0; k < groups.materials.size(); ++k) {
    idx.clear();
    uint32_t lo = UINT32_MAX, hi = 0;
    for (uint32_t o = groups.starts[k]; o < groups.starts[k + 1]; ++o) {
      for (int e = 0; e < 3; ++e) {
        const uint32_t i = m.indices[3 * groups.order[o] + e];
        idx.push_back(i);
        lo = std::min(lo, i);
        hi = std::max(hi, i);
      }
    }
    const size_t at = append(idx.data(), idx.size() * 4);
    tinygltf::Primitive prim = base;
    prim.indices = accessor(view(at, idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, idx.size(), TINYGLTF_TYPE_SCALAR,
                            {double(lo)}, {double(hi)});
    tinygltf::Material mat;
    const uint16_t ci = groups.materials[k];
    mat.name = "color" + std::to_string(ci);
    const Vec3f c = palette.empty() ? Vec3f(0.8f, 0.8f, 0.8f) : palette[ci % palette.size()];
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
  if (!buffer.data.empty()) model.buffers.push_back(std::move(buffer));

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  // Text glTF embeds the buffer as a base64 data URI, so the file stands alone.
  if (!binary && !model.buffers.empty()) model.buffers[0].uri.clear();
  if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/!binary, binary)) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.loc.file = path;
    d.message = "glTF serialisation failed";
    return d;
  }
  AtomicFile f;
  if (Status s = f.Open(path); !s.ok()) return s;
  const std::string data = stream.str();
  if (Status s = f.Write(data); !s.ok()) return s;
  return f.Commit();
}

}  // namespace sylva::mesh
