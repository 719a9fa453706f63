#include "plant/cpfg_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace sylva::plant {
namespace {

struct Lines {
  std::vector<std::string> text;
  size_t next = 0;
  // The next line that is not blank (its 1-based number in *number), or
  // nullptr at the end.
  const std::string* Next(int* number) {
    while (next < text.size()) {
      const std::string& l = text[next++];
      if (l.find_first_not_of(" \t\r") != std::string::npos) {
        *number = int(next);
        return &l;
      }
    }
    return nullptr;
  }
};

Diagnostic SurfaceError(const std::string& path, int line, const std::string& message) {
  return MakeError(SourceLoc{path, line, 0}, message);
}

// Reads "LABEL X: x Y: y Z: z" (any spacing) into v.
bool ReadXyz(const std::string& line, const char* label, Vec3& v) {
  const size_t at = line.find(label);
  if (at == std::string::npos) return false;
  double x, y, z;
  if (std::sscanf(line.c_str() + at + std::char_traits<char>::length(label),
                  " X: %lf Y: %lf Z: %lf", &x, &y, &z) != 3) {
    return false;
  }
  v = Vec3(x, y, z);
  return v.allFinite();
}

// Bernstein weights of the cubic at u.
std::array<double, 4> Bernstein(double u) {
  const double v = 1 - u;
  return {v * v * v, 3 * u * v * v, 3 * u * u * v, u * u * u};
}
std::array<double, 4> BernsteinDerivative(double u) {
  const double v = 1 - u;
  return {-3 * v * v, 3 * v * v - 6 * u * v, 6 * u * v - 3 * u * u, 3 * u * u};
}

}  // namespace

Expected<mesh::TriangleMesh> ParseCpfgSurface(const std::string& text, const std::string& path,
                                              double size, int sPrecision, int tPrecision) {
  Lines lines;
  {
    std::istringstream in(text);
    std::string l;
    while (std::getline(in, l)) lines.text.push_back(l);
  }
  int number = 0;
  const std::string* l = lines.Next(&number);  // the bounding box
  if (!l) return SurfaceError(path, 0, "the surface file is empty");
  l = lines.Next(&number);
  if (l && l->rfind("PRECISION", 0) == 0) {
    int s = 0, t = 0;
    if (std::sscanf(l->c_str(), "PRECISION S: %d T: %d", &s, &t) == 2) {
      if (sPrecision <= 0) sPrecision = s;
      if (tPrecision <= 0) tPrecision = t;
    }
    l = lines.Next(&number);
  }
  Vec3 contact, end, heading, up;
  if (!l || !ReadXyz(*l, "CONTACT POINT", contact)) {
    return SurfaceError(path, number, "expected 'CONTACT POINT  X: x Y: y Z: z'");
  }
  l = lines.Next(&number);
  if (!l || !ReadXyz(*l, "END POINT", end)) {
    return SurfaceError(path, number, "expected 'END POINT  X: x Y: y Z: z'");
  }
  l = lines.Next(&number);
  if (!l || !ReadXyz(*l, "HEADING", heading)) {
    return SurfaceError(path, number, "expected 'HEADING  X: x Y: y Z: z'");
  }
  if (heading.norm() < 1e-6) return SurfaceError(path, number, "the heading has zero length");
  const int headingLine = number;
  l = lines.Next(&number);
  if (!l || !ReadXyz(*l, "UP", up)) {
    return SurfaceError(path, number, "expected 'UP  X: x Y: y Z: z'");
  }
  heading.normalize();
  Vec3 left = heading.cross(up);
  if (left.norm() < 1e-6) {
    return SurfaceError(
        path, number,
        "the up vector is parallel to the heading (line " + std::to_string(headingLine) + ")");
  }
  left.normalize();
  up = left.cross(heading);
  l = lines.Next(&number);
  double fileSize = 0;
  if (!l || std::sscanf(l->c_str(), " SIZE: %lf", &fileSize) != 1 || !std::isfinite(fileSize) ||
      fileSize <= 0) {
    return SurfaceError(path, number, "expected 'SIZE: s' with s > 0");
  }
  const double scale = size / fileSize;
  auto toLocal = [&](const Vec3& p) {
    const Vec3 d = (p - contact) * scale;
    return Vec3(d.dot(left), d.dot(heading), d.dot(up));
  };

  const int ns = std::max(sPrecision, kMinPatchDivisions);
  const int nt = std::max(tPrecision, kMinPatchDivisions);
  mesh::TriangleMesh m;
  int patches = 0;
  while ((l = lines.Next(&number)) != nullptr) {
    // A patch: its name, the colour line, three neighbour lines, 16 points.
    const int nameLine = number;
    for (int skip = 0; skip < 4; ++skip) {
      if (!lines.Next(&number)) {
        return SurfaceError(path, nameLine, "patch '" + *l + "' ends before its control points");
      }
    }
    std::array<Vec3, 16> cp;
    int read = 0;
    while (read < 16) {
      const std::string* row = lines.Next(&number);
      if (!row) {
        return SurfaceError(
            path, nameLine,
            "patch '" + *l + "' has " + std::to_string(read) + " control points, not 16");
      }
      std::istringstream in(*row);
      std::string word;
      std::vector<double> values;
      while (in >> word) {
        char* stop = nullptr;
        const double x = std::strtod(word.c_str(), &stop);
        if (stop != word.c_str() + word.size()) {
          return SurfaceError(path, number, "expected a coordinate, not '" + word + "'");
        }
        if (!std::isfinite(x)) {
          return SurfaceError(path, number, "a control point is not finite: '" + word + "'");
        }
        values.push_back(x);
      }
      if (values.size() % 3 != 0) {
        return SurfaceError(path, number, "a row of control points is not whole x y z triples");
      }
      for (size_t k = 0; k + 2 < values.size() && read < 16; k += 3) {
        cp[size_t(read++)] = toLocal(Vec3(values[k], values[k + 1], values[k + 2]));
      }
    }
    // Evaluate the patch on an (ns+1) x (nt+1) grid; both faces.
    const uint32_t base = uint32_t(m.positions.size());
    for (int i = 0; i <= ns; ++i) {
      const double u = double(i) / ns;
      const auto bu = Bernstein(u), du = BernsteinDerivative(u);
      for (int j = 0; j <= nt; ++j) {
        const double v = double(j) / nt;
        const auto bv = Bernstein(v), dv = BernsteinDerivative(v);
        Vec3 p = Vec3::Zero(), pu = Vec3::Zero(), pv = Vec3::Zero();
        for (int r = 0; r < 4; ++r) {
          for (int c = 0; c < 4; ++c) {
            const Vec3& q = cp[size_t(r * 4 + c)];
            p += bu[size_t(r)] * bv[size_t(c)] * q;
            pu += du[size_t(r)] * bv[size_t(c)] * q;
            pv += bu[size_t(r)] * dv[size_t(c)] * q;
          }
        }
        Vec3 n = pu.cross(pv);
        if (n.norm() < 1e-12) {
          // A degenerate corner (collapsed row): the patch's mean normal.
          n = (cp[15] - cp[0]).cross(cp[12] - cp[3]);
          if (n.norm() < 1e-12) n = Vec3::UnitZ();
        }
        n.normalize();
        m.positions.push_back(p.cast<float>());
        m.normals.push_back(n.cast<float>());
        m.uvs.emplace_back(float(u), float(v));
      }
    }
    // The back face: the same points, normals reversed.
    const uint32_t back = uint32_t(m.positions.size());
    const uint32_t count = back - base;
    for (uint32_t k = 0; k < count; ++k) {
      m.positions.push_back(m.positions[base + k]);
      m.normals.push_back(-m.normals[base + k]);
      m.uvs.push_back(m.uvs[base + k]);
    }
    auto at = [&](int i, int j) { return uint32_t(i * (nt + 1) + j); };
    for (int i = 0; i < ns; ++i) {
      for (int j = 0; j < nt; ++j) {
        const uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
        // Skip triangles of zero area (collapsed patch edges).
        auto add = [&](uint32_t x, uint32_t y, uint32_t z) {
          const Vec3f e = (m.positions[base + y] - m.positions[base + x])
                              .cross(m.positions[base + z] - m.positions[base + x]);
          if (e.norm() <= 1e-12f * std::max(1.0f, float(scale * scale))) return;
          m.indices.insert(m.indices.end(), {base + x, base + y, base + z});
          m.indices.insert(m.indices.end(), {back + x, back + z, back + y});
          m.material.push_back(0);
          m.material.push_back(0);
        };
        add(a, b, c);
        add(a, c, d);
      }
    }
    ++patches;
  }
  if (patches == 0) return SurfaceError(path, number, "the surface file has no patches");
  // Front faces wind counter-clockwise around their normal.
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const Vec3f& p0 = m.positions[m.indices[t]];
    const Vec3f n = (m.positions[m.indices[t + 1]] - p0).cross(m.positions[m.indices[t + 2]] - p0);
    if (n.dot(m.normals[m.indices[t]]) < 0) std::swap(m.indices[t + 1], m.indices[t + 2]);
  }
  return m;
}

}  // namespace sylva::plant
