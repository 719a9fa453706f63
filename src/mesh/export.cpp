// Material grouping, palette and the OBJ and PLY writers. (glTF: export_gltf.cpp.)
#include "mesh/export.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <set>
#include <string_view>
#include <utility>

#include "core/atomic_file.h"
#include "mesh/color.h"

namespace sylva::mesh {

const Palette& DefaultPalette() {
  // Written in sRGB, kept linear.
  static const Palette p = {
      Srgb(0.42f, 0.30f, 0.19f), Srgb(0.24f, 0.50f, 0.16f), Srgb(0.52f, 0.74f, 0.30f),
      Srgb(0.93f, 0.55f, 0.70f), Srgb(0.98f, 0.84f, 0.25f), Srgb(0.95f, 0.95f, 0.92f),
      Srgb(0.26f, 0.18f, 0.11f), Srgb(0.80f, 0.15f, 0.12f),
  };
  return p;
}

std::optional<MeshFormat> FormatFromPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".obj") return MeshFormat::kObj;
  if (ext == ".ply") return MeshFormat::kPly;
  if (ext == ".glb") return MeshFormat::kGlb;
  if (ext == ".gltf") return MeshFormat::kGltf;
  return std::nullopt;
}

MaterialGroups GroupByMaterial(const TriangleMesh& m) {
  MaterialGroups g;
  const size_t nt = m.triangleCount();
  std::vector<uint32_t> count(65536, 0);
  for (uint16_t mat : m.material) ++count[mat];
  std::vector<uint32_t> offset(65536, 0);
  uint32_t total = 0;
  for (size_t k = 0; k < 65536; ++k) {
    if (!count[k]) continue;
    g.materials.push_back(uint16_t(k));
    g.starts.push_back(total);
    offset[k] = total;
    total += count[k];
  }
  g.starts.push_back(total);
  g.order.resize(nt);
  for (uint32_t t = 0; t < nt; ++t) g.order[offset[m.material[t]]++] = t;
  return g;
}

static Vec3f PaletteColor(const Palette& p, uint16_t index) {
  return p.empty() ? Vec3f(0.8f, 0.8f, 0.8f) : p[index % p.size()];
}

// Appends a float the shortest way that reads back exactly.
static inline void Num(std::string& out, float v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, size_t(r.ptr - buf));
}

static inline void UInt(std::string& out, uint32_t v) {
  char buf[16];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, size_t(r.ptr - buf));
}

// The .obj/.mtl pair is two files and two renames, so a crash between them
// could leave an .obj beside an .mtl it does not match. Two rules make every
// pair that can be seen consistent:
// - a material's name is its colour (`kd_0.42_0.3_0.19`: the Kd values, the
//   shortest text that reads back as the same floats), so a name means one
//   definition in every .mtl Sylva writes;
// - the .mtl is committed first as the union of the new materials and those
//   the existing .mtl defines, then the .obj, then (only when the union
//   added anything) the .mtl again with the new materials alone.
// After every rename the .mtl on disk defines every material of the .obj on
// disk, old or new, with the colour that .obj was written with.
static std::string MaterialName(const Vec3f& srgb) {
  std::string name = "kd";
  for (int k = 0; k < 3; ++k) {
    name += '_';
    Num(name, srgb[k]);
  }
  return name;
}

// The `newmtl` blocks of an .mtl file, each with its lines up to the next.
static std::vector<std::pair<std::string, std::string>> MaterialBlocks(const std::string& text) {
  std::vector<std::pair<std::string, std::string>> blocks;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find('\n', at);
    end = end == std::string::npos ? text.size() : end + 1;
    std::string_view line(text.data() + at, end - at);
    if (line.rfind("newmtl ", 0) == 0) {
      std::string_view name = line.substr(7);
      while (!name.empty() && std::isspace(static_cast<unsigned char>(name.back())))
        name.remove_suffix(1);
      blocks.emplace_back(std::string(name), std::string());
    }
    if (!blocks.empty()) blocks.back().second.append(line);
    at = end;
  }
  return blocks;
}

static Status WriteText(const std::string& path, const std::string& text) {
  AtomicFile f;
  if (Status s = f.Open(path); !s.ok()) return s;
  if (Status s = f.Write(text); !s.ok()) return s;
  return f.Commit();
}

Status WriteObj(const TriangleMesh& m, const Palette& palette, const std::string& path) {
  const MaterialGroups groups = GroupByMaterial(m);
  const std::filesystem::path p(path);
  const std::string mtlName = p.stem().string() + ".mtl";
  const std::string mtlPath = (p.parent_path() / mtlName).string();

  // Material names, and the .mtl text that defines them.
  std::vector<std::string> names;
  std::set<std::string> defined;
  std::string text = "# Sylva materials\n";
  for (uint16_t mat : groups.materials) {
    // Kd in sRGB: the values a `palette:` entry was written with.
    const Vec3f c = ToSrgb(PaletteColor(palette, mat));
    names.push_back(MaterialName(c));
    if (!defined.insert(names.back()).second) continue;
    text += "newmtl " + names.back() + "\nKd ";
    Num(text, c.x());
    text += ' ';
    Num(text, c.y());
    text += ' ';
    Num(text, c.z());
    text += "\nKa 0 0 0\nKs 0 0 0\nd 1\nillum 1\n\n";
  }
  AtomicFile obj;
  if (Status s = obj.Open(path); !s.ok()) return s;
  // Written to a device or FIFO (/dev/stdout): no .mtl beside it.
  const bool withMtl = !obj.direct();
  std::string old;  // materials only the existing .mtl defines
  if (withMtl) {
    if (auto existing = ReadFile(mtlPath); existing.ok()) {
      for (auto& [name, block] : MaterialBlocks(*existing)) {
        if (defined.insert(name).second) old += block;
      }
    }
    if (Status s = WriteText(mtlPath, text + old); !s.ok()) return s;
  }
  static constexpr size_t kFlush = 1 << 20;
  std::string out;
  out.reserve(kFlush + 256);
  out = "# Sylva mesh: " + std::to_string(m.vertexCount()) + " vertices, " +
        std::to_string(m.triangleCount()) + " triangles\n" +
        (withMtl ? "mtllib " + mtlName + "\n" : std::string());
  auto flush = [&](bool force) -> Status {
    if (out.size() < kFlush && !force) return {};
    Status s = obj.Write(out);
    out.clear();
    return s;
  };
  // One "v", "vn" or "vt" line per element of an attribute array.
  auto attribute = [&](const char* prefix, const float* data, size_t count, int n) -> Status {
    for (size_t i = 0; i < count; ++i) {
      out += prefix;
      for (int k = 0; k < n; ++k) {
        out += ' ';
        Num(out, data[i * size_t(n) + size_t(k)]);
      }
      out += '\n';
      if (Status s = flush(false); !s.ok()) return s;
    }
    return {};
  };
  static_assert(sizeof(Vec3f) == 3 * sizeof(float) && sizeof(Vec2f) == 2 * sizeof(float));
  // Through float pointers: data() of an empty array is null (no ->data()).
  auto floats = [](const auto& v) { return reinterpret_cast<const float*>(v.data()); };
  if (Status s = attribute("v", floats(m.positions), m.vertexCount(), 3); !s.ok()) return s;
  if (Status s = attribute("vn", floats(m.normals), m.vertexCount(), 3); !s.ok()) return s;
  if (Status s = attribute("vt", floats(m.uvs), m.vertexCount(), 2); !s.ok()) return s;
  for (size_t k = 0; k < groups.materials.size(); ++k) {
    out += "usemtl " + names[k] + "\n";
    for (uint32_t o = groups.starts[k]; o < groups.starts[k + 1]; ++o) {
      const uint32_t t = groups.order[o];
      out += 'f';
      for (int e = 0; e < 3; ++e) {
        const uint32_t i = m.indices[3 * t + e] + 1;
        out += ' ';
        UInt(out, i);
        out += '/';
        UInt(out, i);
        out += '/';
        UInt(out, i);
      }
      out += '\n';
      if (Status s = flush(false); !s.ok()) return s;
    }
  }
  if (Status s = flush(true); !s.ok()) return s;
  if (Status s = obj.Commit(); !s.ok()) return s;
  // The .mtl holds the old materials too until the .obj is in place; then
  // only the new ones.
  return withMtl && !old.empty() ? WriteText(mtlPath, text) : Status();
}

Status WritePly(const TriangleMesh& m, const Palette& palette, const std::string& path) {
  // Vertex colour: the material of the first triangle that uses the vertex.
  std::vector<uint16_t> vmat(m.vertexCount(), 0);
  std::vector<uint8_t> seen(m.vertexCount(), 0);
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = m.indices[3 * t + e];
      if (!seen[i]) {
        seen[i] = 1;
        vmat[i] = m.material[t];
      }
    }
  }
  AtomicFile f;
  if (Status s = f.Open(path); !s.ok()) return s;
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment Sylva mesh\nelement vertex " +
                       std::to_string(m.vertexCount()) +
                       "\nproperty float x\nproperty float y\nproperty float z\n"
                       "property float nx\nproperty float ny\nproperty float nz\n"
                       "property float s\nproperty float t\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                       "element face " +
                       std::to_string(m.triangleCount()) +
                       "\nproperty list uchar uint vertex_indices\nend_header\n";
  if (Status s = f.Write(header); !s.ok()) return s;
  static_assert(sizeof(float) == 4);
  // 8-bit vertex colours are sRGB; one conversion a palette entry.
  std::vector<std::array<uint8_t, 3>> bytes(std::max<size_t>(palette.size(), 1));
  for (size_t k = 0; k < bytes.size(); ++k) {
    const Vec3f c = ToSrgb(PaletteColor(palette, uint16_t(k))) * 255.0f + Vec3f::Constant(0.5f);
    bytes[k] = {uint8_t(c.x()), uint8_t(c.y()), uint8_t(c.z())};
  }
  constexpr size_t kVertexBytes = 8 * 4 + 3;
  std::string buf;
  buf.reserve((1 << 20) + 64);
  auto put = [&](const void* p, size_t n) { buf.append(static_cast<const char*>(p), n); };
  for (size_t i = 0; i < m.vertexCount(); ++i) {
    float v[8] = {m.positions[i].x(), m.positions[i].y(), m.positions[i].z(), m.normals[i].x(),
                  m.normals[i].y(),   m.normals[i].z(),   m.uvs[i].x(),       m.uvs[i].y()};
    put(v, sizeof v);
    put(bytes[vmat[i] % bytes.size()].data(), 3);
    if (buf.size() >= (1 << 20)) {
      if (Status s = f.Write(buf); !s.ok()) return s;
      buf.clear();
    }
  }
  (void)kVertexBytes;
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const uint8_t three = 3;
    put(&three, 1);
    put(&m.indices[3 * t], 12);
    if (buf.size() >= (1 << 20)) {
      if (Status s = f.Write(buf); !s.ok()) return s;
      buf.clear();
    }
  }
  if (Status s = f.Write(buf); !s.ok()) return s;
  return f.Commit();
}

Status WriteMesh(const TriangleMesh& m, const Palette& palette, const std::string& path) {
  // The last defence: never write a file with a NaN or infinity in it.
  if (std::string bad = FindNonFinite(m); !bad.empty()) {
    Diagnostic d;
    d.loc.file = path;
    d.message = "not written: " + bad;
    return d;
  }
  auto format = FormatFromPath(path);
  if (!format) {
    Diagnostic d;
    d.loc.file = path;
    d.message = "unknown mesh format: use .obj, .ply, .glb or .gltf";
    return d;
  }
  switch (*format) {
    case MeshFormat::kObj:
      return WriteObj(m, palette, path);
    case MeshFormat::kPly:
      return WritePly(m, palette, path);
    case MeshFormat::kGlb:
      return WriteGltf(m, palette, path, true);
    case MeshFormat::kGltf:
      return WriteGltf(m, palette, path, false);
  }
  return {};
}

}  // namespace sylva::mesh
