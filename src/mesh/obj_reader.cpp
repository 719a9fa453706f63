#include "mesh/obj_reader.h"

#include <charconv>
#include <cmath>
#include <map>
#include <tuple>

#include "core/atomic_file.h"

namespace sylva::mesh {

Expected<TriangleMesh> ReadObj(const std::string& path) {
  auto text = ReadFile(path, kMaxObjFileBytes);
  if (!text) return text.error();
  return ParseObj(*text, path);
}

Expected<TriangleMesh> ParseObj(const std::string& text, const std::string& path) {
  std::vector<Vec3f> v, vn;
  std::vector<Vec2f> vt;
  TriangleMesh m;
  std::map<std::tuple<int, int, int>, uint32_t> corners;  // (v, vt, vn) -> vertex
  std::vector<bool> needsNormal;
  size_t lineStart = 0;
  int lineNo = 0;
  while (lineStart <= text.size()) {
    size_t lineEnd = text.find('\n', lineStart);
    if (lineEnd == std::string::npos) lineEnd = text.size();
    std::string line = text.substr(lineStart, lineEnd - lineStart);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++lineNo;
    const size_t next = lineEnd + 1;
    auto error = [&](size_t col, const std::string& msg) {
      return MakeError(SourceLoc{path, lineNo, int(col) + 1}, msg, 1, line);
    };
    size_t p = 0;
    auto skip = [&] {
      while (p < line.size() && (line[p] == ' ' || line[p] == '\t')) ++p;
    };
    auto number = [&](float* out) -> bool {
      skip();
      const char* b = line.data() + p;
      auto r = std::from_chars(b, line.data() + line.size(), *out);
      if (r.ec != std::errc() || !std::isfinite(*out)) return false;
      p += size_t(r.ptr - b);
      return true;
    };
    skip();
    if (p >= line.size() || line[p] == '#') {
      lineStart = next;
      continue;
    }
    size_t kw = p;
    while (p < line.size() && line[p] != ' ' && line[p] != '\t') ++p;
    const std::string key = line.substr(kw, p - kw);
    if (key == "v" || key == "vn") {
      Vec3f x;
      for (int k = 0; k < 3; ++k) {
        if (!number(&x[k])) return error(p, "expected a number");
      }
      (key == "v" ? v : vn).push_back(key == "vn" ? x.normalized() : x);
    } else if (key == "vt") {
      Vec2f x;
      for (int k = 0; k < 2; ++k) {
        if (!number(&x[k])) return error(p, "expected a number");
      }
      vt.push_back(x);
    } else if (key == "f") {
      std::vector<uint32_t> face;
      for (;;) {
        skip();
        if (p >= line.size()) break;
        int idx[3] = {0, 0, 0};
        const size_t at = p;
        for (int k = 0; k < 3; ++k) {
          if (k > 0) {
            if (p >= line.size() || line[p] != '/') break;
            ++p;
            if (p < line.size() && line[p] == '/') continue;  // v//vn
          }
          const char* b = line.data() + p;
          auto r = std::from_chars(b, line.data() + line.size(), idx[k]);
          if (r.ec != std::errc()) return error(p, "expected a vertex index");
          p += size_t(r.ptr - b);
        }
        auto resolve = [&](int i, size_t n, const char* what) -> Expected<int> {
          if (i == 0 && std::string(what) != "vertex") return -1;
          int r = i > 0 ? i - 1 : int(n) + i;
          if (r < 0 || size_t(r) >= n)
            return error(at, std::string(what) + " index " + std::to_string(i) + " out of range");
          return r;
        };
        auto a = resolve(idx[0], v.size(), "vertex");
        if (!a) return a.error();
        auto b = resolve(idx[1], vt.size(), "texture");
        if (!b) return b.error();
        auto c = resolve(idx[2], vn.size(), "normal");
        if (!c) return c.error();
        auto key3 = std::make_tuple(*a, *b, *c);
        auto it = corners.find(key3);
        if (it == corners.end()) {
          it = corners.emplace(key3, uint32_t(m.positions.size())).first;
          m.positions.push_back(v[size_t(*a)]);
          m.uvs.push_back(*b >= 0 ? vt[size_t(*b)] : Vec2f(0, 0));
          m.normals.push_back(*c >= 0 ? vn[size_t(*c)] : Vec3f(0, 0, 0));
          needsNormal.push_back(*c < 0);
        }
        face.push_back(it->second);
      }
      if (face.size() < 3) return error(kw, "a face needs at least 3 vertices");
      for (size_t k = 1; k + 1 < face.size(); ++k) {
        const Vec3f n = (m.positions[face[k]] - m.positions[face[0]])
                            .cross(m.positions[face[k + 1]] - m.positions[face[0]]);
        if (!(n.norm() > 0)) continue;  // skip degenerate triangles
        m.indices.insert(m.indices.end(), {face[0], face[k], face[k + 1]});
        m.material.push_back(0);
        for (uint32_t i : {face[0], face[k], face[k + 1]}) {
          if (needsNormal[i]) m.normals[i] += n.normalized();
        }
      }
    }
    lineStart = next;
  }
  for (size_t i = 0; i < m.normals.size(); ++i) {
    if (m.normals[i].norm() > 0) {
      m.normals[i].normalize();
    } else {
      m.normals[i] = Vec3f(0, 0, 1);
    }
  }
  if (m.triangleCount() == 0) {
    return MakeError(SourceLoc{path, 0, 0}, "no faces in this OBJ file");
  }
  return m;
}

}  // namespace sylva::mesh
