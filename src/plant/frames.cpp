#include "plant/frames.h"

#include <algorithm>
#include <set>
#include <string>

#include "lsys/deriver.h"

namespace sylva::plant {
namespace {

Diagnostic Error(const std::string& path, std::string message) {
  Diagnostic d;
  d.loc.file = path;
  d.message = std::move(message);
  return d;
}

// Appends `frame` to `all`, its branch ids after those already there.
void Append(const mesh::PlantGeometry& frame, bool first, mesh::PlantGeometry& all) {
  const uint32_t offset = all.branchCount;
  for (mesh::Segment s : frame.segments) {
    s.branch += offset;
    s.parent += offset;
    all.segments.push_back(s);
  }
  all.polygons.insert(all.polygons.end(), frame.polygons.begin(), frame.polygons.end());
  all.surfaces.insert(all.surfaces.end(), frame.surfaces.begin(), frame.surfaces.end());
  all.spheres.insert(all.spheres.end(), frame.spheres.begin(), frame.spheres.end());
  all.tubes.insert(all.tubes.end(), frame.tubes.begin(), frame.tubes.end());
  for (uint32_t b : frame.loops) all.loops.push_back(b + offset);
  all.branchCount += std::max<uint32_t>(frame.branchCount, 1);
  if (first) {
    all.boundsMin = frame.boundsMin;
    all.boundsMax = frame.boundsMax;
    all.planar = frame.planar;
    all.widthInPixels = frame.widthInPixels;
    all.cylinderStyle = frame.cylinderStyle;
  } else {
    all.boundsMin = all.boundsMin.cwiseMin(frame.boundsMin);
    all.boundsMax = all.boundsMax.cwiseMax(frame.boundsMax);
    all.planar = all.planar && frame.planar;
  }
}

size_t Primitives(const mesh::PlantGeometry& g) {
  size_t n = g.segments.size() + g.spheres.size() + g.surfaces.size();
  for (const mesh::Polygon& p : g.polygons) n += p.vertices.size();
  for (const mesh::ContourTube& t : g.tubes) n += t.points.size();
  return n;
}

}  // namespace

Expected<mesh::PlantGeometry> DrawFrames(const PlantSpec& spec, const FrameRange& range,
                                         DiagnosticList& diagnostics) {
  const std::string& path = spec.path;
  FrameRange frames = range;
  if (frames.last < 0) {
    // The derivation length: the spec's, else the grammar's.
    auto probe = Grower::Start(spec, diagnostics);
    if (!probe) return Error(path, "the grammar has errors");
    frames.last = probe->steps();
  }
  if (frames.first < 0 || frames.last < frames.first || frames.step < 1 ||
      frames.last > lsys::kMaxAnimationSteps) {
    return Error(path, "animation frames " + std::to_string(frames.first) + " to " +
                           std::to_string(frames.last) + " every " + std::to_string(frames.step) +
                           ": expected 0 <= first <= last <= " +
                           std::to_string(lsys::kMaxAnimationSteps) + " and a step of at least 1");
  }
  PlantSpec s = spec;
  s.steps = frames.last;
  auto grower = Grower::Start(s, diagnostics);
  if (!grower) return Error(path, "the grammar has errors");
  const uint64_t maxPrimitives = std::max<uint64_t>(1, spec.limits.maxTriangles / 4);
  mesh::PlantGeometry all;
  std::set<std::string> seen;  // turtle warnings, once each
  bool first = true;
  for (int step = 0;; ++step) {
    if (step >= frames.first && (step - frames.first) % frames.step == 0) {
      DiagnosticList turtle;
      auto g = grower->Draw(&turtle);
      if (!g) return g.error();
      for (Diagnostic& d : turtle.items)
        if (seen.insert(d.message).second) diagnostics.Add(std::move(d));
      if (Primitives(all) + Primitives(*g) > maxPrimitives) {
        return Error(path, "the animation frames " + std::to_string(frames.first) + " to " +
                               std::to_string(step) + " draw more than " +
                               std::to_string(maxPrimitives) +
                               " primitives together (a quarter of --max-triangles)");
      }
      Append(*g, first, all);
      first = false;
    }
    if (step >= frames.last) break;
    if (Status st = grower->Step(); !st.ok()) return st.error();
  }
  return all;
}

}  // namespace sylva::plant
