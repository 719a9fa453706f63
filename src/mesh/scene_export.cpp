// glTF 2.0 scenes through tinygltf (the document) and mesh/glb.h (the
// container). One buffer: for each mesh its positions, normals and UVs and
// one index block per material, then each point set's positions and
// colours; every part is a multiple of 4 bytes, so every view is aligned.
// The buffer is described as a list of pieces pointing into the caller's
// arrays (indices regrouped by material are the only copy), streamed into
// the .glb or gathered into the .gltf's data URI.
#include "mesh/scene_export.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "mesh/color.h"
#include "mesh/glb.h"

namespace sylva::mesh {

std::optional<Trs> DecomposeTrs(const Mat4f& mf, std::string* why) {
  auto fail = [&](const char* reason) -> std::optional<Trs> {
    if (why) *why = reason;
    return std::nullopt;
  };
  const Eigen::Matrix4d m = mf.cast<double>();
  if (!m.allFinite()) return fail("a number in the transform is not finite");
  if (std::abs(m(3, 0)) > 1e-6 || std::abs(m(3, 1)) > 1e-6 || std::abs(m(3, 2)) > 1e-6 ||
      std::abs(m(3, 3) - 1) > 1e-6)
    return fail("the transform's bottom row is not (0 0 0 1) (a projection)");
  const Eigen::Matrix3d a = m.block<3, 3>(0, 0);
  Eigen::Vector3d s(a.col(0).norm(), a.col(1).norm(), a.col(2).norm());
  const double largest = s.maxCoeff();
  Trs t;
  t.translation = m.block<3, 1>(0, 3).cast<float>();
  if (largest == 0) {
    t.scale = Vec3f::Zero();
    return t;
  }
  // Unit axes; an axis scaled to zero is completed from the others,
  // right-handed.
  Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
  int zeros = 0, kept = 0;
  for (int i = 0; i < 3; ++i) {
    if (s[i] <= 1e-7 * largest) {
      s[i] = 0;
      ++zeros;
    } else {
      r.col(i) = a.col(i) / s[i];
      kept = i;
    }
  }
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (std::abs(r.col(i).dot(r.col(j))) > 1e-3)
        return fail(
            "the transform shears (its axes are not orthogonal), which glTF's "
            "translation, rotation and scale cannot express");
  if (zeros == 1) {
    for (int i = 0; i < 3; ++i)
      if (s[i] == 0) r.col(i) = r.col((i + 1) % 3).cross(r.col((i + 2) % 3));
  } else if (zeros == 2) {
    const Eigen::Vector3d x = r.col(kept);
    const Eigen::Vector3d u =
        (std::abs(x.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY())
            .cross(x)
            .normalized();
    r.col((kept + 1) % 3) = u;
    r.col((kept + 2) % 3) = x.cross(u);
  }
  if (r.determinant() < 0) {  // a mirror: glTF takes a negative scale
    s.x() = -s.x();
    r.col(0) = -r.col(0);
  }
  Eigen::Quaterniond q(r);
  q.normalize();
  t.rotation = q.cast<float>();
  t.scale = s.cast<float>();
  return t;
}

namespace {

struct Piece {
  const void* data;
  size_t bytes;
};

// The buffer as pieces; parts made here (regrouped indices) live in `owned`.
struct Buffer {
  std::vector<Piece> pieces;
  std::deque<std::vector<uint32_t>> owned;
  size_t total = 0;
  size_t Add(const void* p, size_t bytes) {
    const size_t at = total;
    pieces.push_back({p, bytes});
    total += bytes;  // every part is a multiple of 4 bytes
    return at;
  }
};

Status Error(const std::string& path, const std::string& message) {
  Diagnostic d;
  d.kind = ErrorKind::kRuntime;
  d.loc.file = path;
  d.message = message;
  return d;
}

// A tint rounded to 8-bit sRGB, packed as 0xRRGGBB.
uint32_t TintKey(const Vec3f& tint) {
  uint32_t key = 0;
  for (int i = 0; i < 3; ++i) {
    const float c = LinearToSrgb(std::clamp(tint[i], 0.0f, 1.0f));
    key = key << 8 | uint32_t(std::lround(c * 255));
  }
  return key;
}

Vec3f TintOf(uint32_t key) {
  return Srgb(float(key >> 16 & 255) / 255, float(key >> 8 & 255) / 255, float(key & 255) / 255);
}

class Writer {
 public:
  Writer(const ExportScene& scene, const std::string& path) : scene_(scene), path_(path) {
    model_.asset.version = "2.0";
    model_.asset.generator = "Sylva";
  }

  Status Build() {
    primitives_.resize(scene_.meshes.size());
    for (size_t i = 0; i < scene_.meshes.size(); ++i)
      if (Status s = AddMesh(i); !s.ok()) return s;
    tinygltf::Scene root;
    root.name = "Sylva";
    for (const SceneNode& n : scene_.nodes) {
      if (n.mesh < 0 || size_t(n.mesh) >= scene_.meshes.size())
        return Error(path_, "node '" + n.name + "' names mesh " + std::to_string(n.mesh) + " of " +
                                std::to_string(scene_.meshes.size()));
      if (primitives_[size_t(n.mesh)].empty()) continue;  // no triangles
      if (!n.tint.allFinite()) return Error(path_, "node '" + n.name + "': its tint is not finite");
      std::string why;
      const std::optional<Trs> trs = DecomposeTrs(n.transform, &why);
      if (!trs) return Error(path_, "node '" + n.name + "': " + why);
      tinygltf::Node node;
      node.name = n.name;
      node.mesh = MeshFor(size_t(n.mesh), TintKey(n.tint));
      const Quatf& q = trs->rotation;
      node.translation = {trs->translation.x(), trs->translation.y(), trs->translation.z()};
      node.rotation = {q.x(), q.y(), q.z(), q.w()};
      node.scale = {trs->scale.x(), trs->scale.y(), trs->scale.z()};
      root.nodes.push_back(int(model_.nodes.size()));
      model_.nodes.push_back(std::move(node));
    }
    for (const ScenePoints& p : scene_.points) {
      const int node = AddPoints(p);
      if (node == -2) return pointsError_;
      if (node >= 0) root.nodes.push_back(node);
    }
    model_.scenes.push_back(root);
    model_.defaultScene = 0;
    stats_.nodes = model_.nodes.size();
    stats_.meshes = model_.meshes.size();
    stats_.materials = model_.materials.size();
    return {};
  }

  Status Write(bool binary) {
    tinygltf::TinyGLTF writer;
    if (!binary) {
      if (buffer_.total > 0) {
        tinygltf::Buffer b;
        b.data.reserve(buffer_.total);
        for (const Piece& p : buffer_.pieces) {
          const auto* bytes = static_cast<const unsigned char*>(p.data);
          b.data.insert(b.data.end(), bytes, bytes + p.bytes);
        }
        model_.buffers.push_back(std::move(b));
      }
      std::ostringstream stream;
      if (!writer.WriteGltfSceneToStream(&model_, stream, /*prettyPrint=*/true, false))
        return Error(path_, "glTF serialisation failed");
      AtomicFile f;
      if (Status s = f.Open(path_); !s.ok()) return s;
      if (Status s = f.Write(stream.str()); !s.ok()) return s;
      return f.Commit();
    }
    if (buffer_.total > 0) {
      tinygltf::Buffer placeholder;
      placeholder.uri = "bin";  // replaced below: the GLB buffer has no uri
      model_.buffers.push_back(placeholder);
    }
    std::ostringstream stream;
    if (!writer.WriteGltfSceneToStream(&model_, stream, false, false))
      return Error(path_, "glTF serialisation failed");
    nlohmann::json doc = nlohmann::json::parse(stream.str(), nullptr, false);
    if (doc.is_discarded()) return Error(path_, "glTF serialisation failed");
    if (buffer_.total > 0)
      doc["buffers"] = nlohmann::json::array({{{"byteLength", buffer_.total}}});
    return WriteGlb(
        path_, doc.dump(), buffer_.total,
        [&](const ByteSink& sink) -> Status {
          for (const Piece& p : buffer_.pieces)
            if (Status s = sink(p.data, p.bytes); !s.ok()) return s;
          return {};
        },
        "scene too large for a .glb file (over 4 GiB); use .gltf, fewer sides or fewer "
        "particles");
  }

  const SceneExportStats& stats() const { return stats_; }

 private:
  int View(const void* data, size_t bytes, int target) {
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer_.Add(data, bytes);
    v.byteLength = bytes;
    v.target = target;
    model_.bufferViews.push_back(v);
    return int(model_.bufferViews.size() - 1);
  }

  int Accessor(int view, int componentType, size_t count, int type, std::vector<double> lo = {},
               std::vector<double> hi = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = componentType;
    a.count = count;
    a.type = type;
    a.minValues = std::move(lo);
    a.maxValues = std::move(hi);
    model_.accessors.push_back(a);
    return int(model_.accessors.size() - 1);
  }

  int Vec3Accessor(const std::vector<Vec3f>& v, bool bounds) {
    std::vector<double> lo, hi;
    if (bounds) {
      Vec3f a = v[0], b = v[0];
      for (const Vec3f& p : v) {
        a = a.cwiseMin(p);
        b = b.cwiseMax(p);
      }
      lo = {a.x(), a.y(), a.z()};
      hi = {b.x(), b.y(), b.z()};
    }
    return Accessor(View(v.data(), v.size() * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                    TINYGLTF_COMPONENT_TYPE_FLOAT, v.size(), TINYGLTF_TYPE_VEC3, lo, hi);
  }

  // Accessors of one mesh, with one primitive per material (its colour
  // index kept beside it until a tint gives it a material).
  Status AddMesh(size_t i) {
    const SceneMesh& sm = scene_.meshes[i];
    if (!sm.mesh || sm.mesh->triangleCount() == 0) return {};
    const TriangleMesh& m = *sm.mesh;
    const size_t nv = m.vertexCount();
    const std::string name = "mesh '" + sm.name + "': ";
    if (m.normals.size() != nv || m.uvs.size() != nv || m.indices.size() % 3 != 0 ||
        m.material.size() != m.triangleCount())
      return Error(path_, name + "array lengths disagree");
    if (std::string bad = FindNonFinite(m); !bad.empty()) return Error(path_, name + bad);
    tinygltf::Primitive base;
    base.mode = TINYGLTF_MODE_TRIANGLES;
    base.attributes["POSITION"] = Vec3Accessor(m.positions, true);
    base.attributes["NORMAL"] = Vec3Accessor(m.normals, false);
    base.attributes["TEXCOORD_0"] =
        Accessor(View(m.uvs.data(), nv * 8, TINYGLTF_TARGET_ARRAY_BUFFER),
                 TINYGLTF_COMPONENT_TYPE_FLOAT, nv, TINYGLTF_TYPE_VEC2);
    const MaterialGroups groups = GroupByMaterial(m);
    for (size_t k = 0; k < groups.materials.size(); ++k) {
      std::vector<uint32_t>& block = buffer_.owned.emplace_back();
      uint32_t lo = UINT32_MAX, hi = 0;
      for (uint32_t o = groups.starts[k]; o < groups.starts[k + 1]; ++o) {
        for (int e = 0; e < 3; ++e) {
          const uint32_t v = m.indices[3 * size_t(groups.order[o]) + e];
          lo = std::min(lo, v);
          hi = std::max(hi, v);
          block.push_back(v);
        }
      }
      if (hi >= nv)
        return Error(path_, name + "index " + std::to_string(hi) + " is past its " +
                                std::to_string(nv) + " vertices");
      tinygltf::Primitive prim = base;
      prim.indices =
          Accessor(View(block.data(), block.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, block.size(), TINYGLTF_TYPE_SCALAR,
                   {double(lo)}, {double(hi)});
      primitives_[i].push_back({prim, groups.materials[k]});
    }
    return {};
  }

  int Material(Vec3f c) {
    c = c.cwiseMax(0.0f).cwiseMin(1.0f);
    const std::array<float, 3> key{c.x(), c.y(), c.z()};
    if (auto it = materials_.find(key); it != materials_.end()) return it->second;
    tinygltf::Material mat;
    const Vec3f s = ToSrgb(c) * 255;
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%02x%02x%02x", int(std::lround(s.x())),
                  int(std::lround(s.y())), int(std::lround(s.z())));
    mat.name = hex;
    mat.pbrMetallicRoughness.baseColorFactor = {c.x(), c.y(), c.z(), 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.9;
    mat.doubleSided = true;
    model_.materials.push_back(mat);
    return materials_[key] = int(model_.materials.size() - 1);
  }

  // The glTF mesh of scene mesh `i` drawn with `tint`, made on first use;
  // every tint of a mesh shares its accessors.
  int MeshFor(size_t i, uint32_t tintKey) {
    const auto key = std::make_pair(i, tintKey);
    if (auto it = meshes_.find(key); it != meshes_.end()) return it->second;
    const SceneMesh& sm = scene_.meshes[i];
    const Vec3f tint = TintOf(tintKey);
    tinygltf::Mesh mesh;
    mesh.name = sm.name;
    if (tintKey != 0xFFFFFF) {
      char hex[16];
      std::snprintf(hex, sizeof hex, " tint #%06x", unsigned(tintKey));
      mesh.name += hex;
    }
    for (const auto& [prim, colorIndex] : primitives_[i]) {
      const Vec3f c =
          sm.palette.empty() ? Srgb(0.8f, 0.8f, 0.8f) : sm.palette[colorIndex % sm.palette.size()];
      tinygltf::Primitive p = prim;
      p.material = Material(c.cwiseProduct(tint));
      mesh.primitives.push_back(std::move(p));
    }
    model_.meshes.push_back(std::move(mesh));
    return meshes_[key] = int(model_.meshes.size() - 1);
  }

  // A node with a POINTS or LINES mesh; -1 when empty, -2 on an error
  // (left in pointsError_).
  int AddPoints(const ScenePoints& p) {
    const std::string name = "points '" + p.name + "': ";
    if (p.colors.size() != p.positions.size()) {
      pointsError_ = Error(path_, name + "one colour per point is needed");
      return -2;
    }
    if (p.mode == PointMode::kLines && p.positions.size() % 2 != 0) {
      pointsError_ = Error(path_, name + "lines need an even number of points");
      return -2;
    }
    if (p.positions.empty()) return -1;
    for (size_t k = 0; k < p.positions.size(); ++k) {
      if (!p.positions[k].allFinite() || !p.colors[k].allFinite()) {
        pointsError_ = Error(path_, name + "point " + std::to_string(k) + " is not finite");
        return -2;
      }
    }
    std::vector<Vec3f>& colors = clamped_.emplace_back(p.colors);
    for (Vec3f& c : colors) c = c.cwiseMax(0.0f).cwiseMin(1.0f);
    tinygltf::Primitive prim;
    prim.mode = p.mode == PointMode::kPoints ? TINYGLTF_MODE_POINTS : TINYGLTF_MODE_LINE;
    prim.attributes["POSITION"] = Vec3Accessor(p.positions, true);
    prim.attributes["COLOR_0"] = Vec3Accessor(colors, false);
    tinygltf::Mesh mesh;
    mesh.name = p.name;
    mesh.primitives.push_back(prim);
    model_.meshes.push_back(std::move(mesh));
    tinygltf::Node node;
    node.name = p.name;
    node.mesh = int(model_.meshes.size() - 1);
    model_.nodes.push_back(std::move(node));
    (p.mode == PointMode::kPoints ? stats_.points : stats_.lines) +=
        p.mode == PointMode::kPoints ? p.positions.size() : p.positions.size() / 2;
    return int(model_.nodes.size() - 1);
  }

  const ExportScene& scene_;
  const std::string& path_;
  tinygltf::Model model_;
  Buffer buffer_;
  std::vector<std::vector<std::pair<tinygltf::Primitive, uint16_t>>> primitives_;
  std::map<std::array<float, 3>, int> materials_;
  std::map<std::pair<size_t, uint32_t>, int> meshes_;
  std::deque<std::vector<Vec3f>> clamped_;
  Status pointsError_;
  SceneExportStats stats_;
};

}  // namespace

Status WriteSceneGltf(const ExportScene& scene, const std::string& path, bool binary,
                      SceneExportStats* stats) {
  static_assert(sizeof(Vec3f) == 12 && sizeof(Vec2f) == 8);
  Writer w(scene, path);
  if (Status s = w.Build(); !s.ok()) return s;
  if (Status s = w.Write(binary); !s.ok()) return s;
  if (stats) *stats = w.stats();
  return {};
}

}  // namespace sylva::mesh
