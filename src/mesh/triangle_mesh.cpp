#include "mesh/triangle_mesh.h"

#include <cmath>

namespace sylva::mesh {

void TriangleMesh::Clear() {
  positions.clear();
  normals.clear();
  uvs.clear();
  indices.clear();
  material.clear();
  coverage.clear();
}

void TriangleMesh::Append(const TriangleMesh& o) {
  const uint32_t base = uint32_t(positions.size());
  if (!coverage.empty() || !o.coverage.empty()) {
    coverage.resize(positions.size(), 1.0f);
    if (o.coverage.empty()) {
      coverage.resize(positions.size() + o.positions.size(), 1.0f);
    } else {
      coverage.insert(coverage.end(), o.coverage.begin(), o.coverage.end());
    }
  }
  positions.insert(positions.end(), o.positions.begin(), o.positions.end());
  normals.insert(normals.end(), o.normals.begin(), o.normals.end());
  uvs.insert(uvs.end(), o.uvs.begin(), o.uvs.end());
  indices.reserve(indices.size() + o.indices.size());
  for (uint32_t i : o.indices) indices.push_back(base + i);
  material.insert(material.end(), o.material.begin(), o.material.end());
}

std::string FindNonFinite(const TriangleMesh& m) {
  // allFinite() is false for NaN and infinity in any component.
  auto bad = [&](const auto& array, const char* what) -> std::string {
    for (size_t i = 0; i < array.size(); ++i) {
      if (!array[i].allFinite())
        return std::string(what) + " of vertex " + std::to_string(i) + " is not finite";
    }
    return {};
  };
  if (std::string s = bad(m.positions, "the position"); !s.empty()) return s;
  if (std::string s = bad(m.normals, "the normal"); !s.empty()) return s;
  for (size_t i = 0; i < m.coverage.size(); ++i) {
    if (!std::isfinite(m.coverage[i]))
      return "the coverage of vertex " + std::to_string(i) + " is not finite";
  }
  return bad(m.uvs, "the texture coordinate");
}

std::string Validate(const TriangleMesh& m, float areaEpsilon) {
  const size_t n = m.positions.size();
  if (m.normals.size() != n || m.uvs.size() != n) return "attribute arrays differ in size";
  if (m.indices.size() % 3) return "index count is not a multiple of 3";
  if (m.material.size() != m.triangleCount()) return "one material per triangle expected";
  if (!m.coverage.empty() && m.coverage.size() != n) return "coverage array differs in size";
  for (size_t i = 0; i < m.coverage.size(); ++i) {
    if (!(m.coverage[i] > 0 && m.coverage[i] <= 1))
      return "coverage " + std::to_string(i) + " is " + std::to_string(m.coverage[i]) +
             ", outside (0, 1]";
  }
  for (size_t i = 0; i < n; ++i) {
    if (!m.positions[i].allFinite() || !m.normals[i].allFinite() || !m.uvs[i].allFinite())
      return "vertex " + std::to_string(i) + " is not finite";
    if (std::abs(m.normals[i].norm() - 1) > 1e-4f)
      return "normal " + std::to_string(i) + " has length " + std::to_string(m.normals[i].norm());
  }
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const uint32_t a = m.indices[3 * t], b = m.indices[3 * t + 1], c = m.indices[3 * t + 2];
    if (a >= n || b >= n || c >= n)
      return "triangle " + std::to_string(t) + " has an index out of range";
    const Eigen::Vector3d pa = m.positions[a].cast<double>(), pb = m.positions[b].cast<double>(),
                          pc = m.positions[c].cast<double>();
    const double area = 0.5 * (pb - pa).cross(pc - pa).norm();
    if (!(area > areaEpsilon))
      return "triangle " + std::to_string(t) + " has zero area (" + std::to_string(area) + ")";
  }
  return {};
}

}  // namespace sylva::mesh
