// How render and the viewer show a grammar's plant: see plant_view.h.
#include "app/plant_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "render/renderer.h"
#include "scene/default_scene.h"

namespace sylva::app {

bool WiderThanAPixel(const mesh::PlantGeometry& g) {
  if (!g.widthInPixels) return false;
  for (const mesh::Segment& s : g.segments)
    if (std::max(s.radiusStart, s.radiusEnd) > 0.5f + 1e-4f) return true;
  return false;
}

PlantView ChoosePlantView(const std::string& grammarPath, const ViewFile* view,
                          const mesh::PlantGeometry* geometry, const double* camera) {
  PlantView v;
  if (geometry && plant::IsLineFigure(*geometry))
    v.look = WiderThanAPixel(*geometry) ? PlantLook::kRibbons : PlantLook::kLines;
  // cpfg's default view (interpret.c, InitializeParameters): from
  // viewpoint 0,0,1 toward the origin, in parallel projection, for a `.l`
  // without a view file.
  const bool hasViewFile = view && !view->path.empty();
  const bool cpfgDefaultView =
      !hasViewFile && std::filesystem::path(grammarPath).extension() == ".l";
  v.cpfgObject = view || cpfgDefaultView;
  v.orthographic = v.figure() || cpfgDefaultView || (view && view->parallel);
  const auto direction = view ? ViewDirection(*view) : std::nullopt;
  if (camera) {
    v.cameraFlag = true;
    v.azimuth = camera[0];
    v.elevation = camera[1];
    v.distance = camera[2];
  } else if (direction) {
    v.azimuth = (*direction)[0];
    v.elevation = (*direction)[1];
  } else if (cpfgDefaultView || v.figure()) {
    v.azimuth = v.elevation = 0;
  }
  if (view && !camera) {
    v.scale = view->scale;
    if (!v.orthographic) v.viewingAngle = view->viewingAngle;
    if (v.orthographic) v.viewBox = view->box;
    if (hasViewFile && !v.orthographic && (view->viewpoint || view->target)) {
      const Vec3 at = view->target.value_or(Vec3(0, 0, 0));
      const double d =
          (view->viewpoint.value_or(Vec3(0, 0, 1)) - at).norm() / view->scale.value_or(1);
      if (d > 0 && std::isfinite(d)) {
        v.cpfgTarget = at;
        v.cpfgDistance = d;
      }
    }
  }
  v.keyFromViewFile = view && view->lightToward;
  v.keyToward = v.keyFromViewFile ? *view->lightToward : render::KeyLightDirection();
  return v;
}

Expected<mesh::Box> FramedBox(const PlantView& view, const plant::Plant& plant,
                              const plant::PlantSpec& spec) {
  auto valid = [](const mesh::Box& b) { return (b.lo.array() <= b.hi.array()).all(); };
  mesh::Box box{plant.geometry.boundsMin, plant.geometry.boundsMax};
  if (!view.figure()) {
    auto meshBox = plant::MeshBounds(plant, spec);
    if (!meshBox) return meshBox.error();
    if (valid(*meshBox)) box = *meshBox;
  }
  if (!valid(box)) box = mesh::Box{Vec3::Zero(), Vec3::Ones()};
  return box;
}

render::Camera FramePlant(const PlantView& view, const mesh::Box& box, double aspect) {
  const bool boxed = view.orthographic && view.viewBox;
  render::Camera camera = render::Camera::Frame(boxed ? (*view.viewBox)[0] : box.lo,
                                                boxed ? (*view.viewBox)[1] : box.hi, aspect,
                                                view.azimuth, view.elevation, view.orthographic);
  if (view.distance > 0) camera.distance = view.distance;
  if (view.cpfgDistance > 0 && !camera.orthographic) {
    camera.target = view.cpfgTarget;
    camera.distance = view.cpfgDistance;
    camera.fovY = view.viewingAngle.value_or(45);
    // cpfg clips at its `back distance:` (100000 by default), far beyond
    // a plant; Sylva's far plane (4 distances + 1 by default) reaches the
    // box's farthest corner, so a scene larger than the eye's distance to
    // the view reference point (corpus3's forest: 3000 units wide, seen
    // from 200) is not cut off.
    const Vec3 eye = camera.Eye();
    double reach = 0;
    for (int k = 0; k < 8; ++k) {
      const Vec3 c((k & 1) ? box.hi.x() : box.lo.x(), (k & 2) ? box.hi.y() : box.lo.y(),
                   (k & 4) ? box.hi.z() : box.lo.z());
      reach = std::max(reach, (c - eye).norm());
    }
    if (std::isfinite(reach)) camera.farPlane = std::max(camera.distance * 4 + 1, reach * 1.01);
    return camera;
  }
  // cpfg's `viewing angle:` is the perspective's field of view: the camera
  // moves back or forward so the framed box keeps its size (the distance
  // times tan(35/2) / tan(a/2)). Its `scale factor:` zooms the framed view.
  if (view.viewingAngle && !camera.orthographic) {
    const double a = *view.viewingAngle;
    camera.distance *= std::tan(camera.fovY * kDegToRad / 2) / std::tan(a * kDegToRad / 2);
    camera.fovY = a;
  }
  if (view.scale) {
    if (camera.orthographic)
      camera.orthoHeight /= *view.scale;  // the eye stays outside the plant
    else
      camera.distance /= *view.scale;
  }
  return camera;
}

namespace {

// The clip planes a point lies beyond, one bit each (x < -w, x > w, y < -w,
// y > w, z < -w, z > w); 0: inside the view.
int Outcode(const Mat4& m, const Vec3& p) {
  const Vec4 c = m * Vec4(p.x(), p.y(), p.z(), 1.0);
  int code = 0;
  for (int a = 0; a < 3; ++a) {
    if (c[a] < -c.w()) code |= 1 << (2 * a);
    if (c[a] > c.w()) code |= 1 << (2 * a + 1);
  }
  return code;
}

}  // namespace

bool SeesBox(const render::Camera& camera, double aspect, const mesh::Box& box) {
  const Mat4 m = camera.ViewProjection(aspect);
  int all = ~0;
  for (int k = 0; k < 8; ++k)
    all &= Outcode(m, Vec3((k & 1) ? box.hi.x() : box.lo.x(), (k & 2) ? box.hi.y() : box.lo.y(),
                           (k & 4) ? box.hi.z() : box.lo.z()));
  return all == 0;
}

bool SeesAnyOf(const render::Camera& camera, double aspect, const mesh::PlantGeometry& g) {
  if (!g.surfaces.empty()) return true;
  const Mat4 m = camera.ViewProjection(aspect);
  // The clip planes all corners of the box [lo, hi] lie beyond.
  auto boxCode = [&m](const Vec3& lo, const Vec3& hi) {
    int all = ~0;
    for (int k = 0; k < 8; ++k)
      all &= Outcode(
          m, Vec3((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z()));
    return all;
  };
  for (const mesh::Segment& s : g.segments) {
    const double r = std::max(s.radiusStart, s.radiusEnd);
    const Vec3 lo = s.start.cwiseMin(s.end).array() - r, hi = s.start.cwiseMax(s.end).array() + r;
    if (boxCode(lo, hi) == 0) return true;
  }
  for (const mesh::Sphere& s : g.spheres)
    if (boxCode(s.center.array() - s.radius, s.center.array() + s.radius) == 0) return true;
  auto pointsCode = [&m](const std::vector<Vec3>& points) {
    int all = points.empty() ? 1 : ~0;
    for (const Vec3& p : points) all &= Outcode(m, p);
    return all;
  };
  for (const mesh::Polygon& p : g.polygons)
    if (pointsCode(p.vertices) == 0) return true;
  for (const mesh::ContourTube& t : g.tubes)
    if (pointsCode(t.points) == 0) return true;
  return false;
}

std::optional<Diagnostic> UnseenPlantWarning(const PlantView& view, const ViewFile* viewFile,
                                             const render::Camera& camera, double aspect,
                                             const mesh::Box& box, const mesh::PlantGeometry& g) {
  const bool perspective = view.cpfgDistance > 0 && !camera.orthographic;
  const bool boxed = view.orthographic && view.viewBox;
  if (!viewFile || viewFile->path.empty() || view.cameraFlag || !(perspective || boxed))
    return std::nullopt;
  // A plant that draws nothing has nothing to miss (its own warnings say
  // why it is empty).
  if (g.segments.empty() && g.polygons.empty() && g.surfaces.empty() && g.spheres.empty() &&
      g.tubes.empty())
    return std::nullopt;
  if (SeesBox(camera, aspect, box) && SeesAnyOf(camera, aspect, g)) return std::nullopt;
  auto xyz = [](const Vec3& p) {
    char b[128];
    std::snprintf(b, sizeof b, "%g,%g,%g", p.x(), p.y(), p.z());
    return std::string(b);
  };
  Diagnostic d;
  d.severity = Severity::kWarning;
  d.loc.file = viewFile->path;
  d.loc.line = perspective ? viewFile->cameraLine : viewFile->boxLine;
  d.loc.column = d.loc.line > 0 ? 1 : 0;
  const std::string plant = "the plant (from " + xyz(box.lo) + " to " + xyz(box.hi) + ")";
  if (perspective) {
    d.message = "the view file's camera sees none of " + plant + ": the eye at " +
                xyz(camera.Eye()) + " looks toward the view reference point " + xyz(camera.target) +
                " with a field of " + std::to_string(int(camera.fovY + 0.5)) +
                " degrees, as cpfg's camera does (vrp + (viewpoint - vrp) / scale), and the "
                "picture is empty; --camera AZIMUTH,ELEVATION,0 frames the plant";
  } else {
    d.message = "the view file's 'box:' holds none of " + plant +
                ": the picture is empty; --camera AZIMUTH,ELEVATION,0 frames the plant";
  }
  return d;
}

render::Camera FrameAll(const PlantView& view, const mesh::Box& box, double aspect, double azimuth,
                        double elevation) {
  PlantView all = view;
  all.azimuth = azimuth;
  all.elevation = elevation;
  all.distance = 0;
  all.scale.reset();
  all.cpfgDistance = 0;  // everything shows: the box framed
  all.viewBox.reset();
  return FramePlant(all, box, aspect);
}

mesh::ScreenView ScreenViewFor(const PlantView& view, const render::Camera& camera, int width,
                               int height, double eps, const mesh::Box& box,
                               double shadowTexelsScale, const mesh::PlantGeometry& geometry) {
  mesh::ScreenView s;
  s.viewProjection = camera.ViewProjection(double(width) / height);
  s.width = width;
  s.height = height;
  s.eps = eps;
  // Shadows of what lies outside the view may fall inside it (a 2D
  // figure's ribbons cast none).
  if (view.look == PlantLook::kMesh) {
    s.shadowFrom = view.keyToward;
    s.shadowPlaneY = box.lo.y();
    s.shadowTexelsPerUnit = render::ShadowTexelsPerUnit(box) * shadowTexelsScale;
  }
  // Twigs under a pixel fade as coverage lines (the renderer blends them).
  s.coverage = true;
  if (view.look == PlantLook::kRibbons) {
    // A 2D figure's pixel-wide lines are flat ribbons, never tubes
    // (ribbons are drawn under 3 eps of radius).
    float widest = 0;
    for (const mesh::Segment& seg : geometry.segments)
      widest = std::max({widest, 2 * seg.radiusStart, 2 * seg.radiusEnd});
    s.eps = std::max(s.eps, 0.2 * widest);
  }
  return s;
}

draw::DrawList PlantScene(const PlantView& view, std::shared_ptr<const mesh::TriangleMesh> mesh,
                          const mesh::Palette& palette, draw::Lines lines, const mesh::Box& box,
                          const render::Camera& camera) {
  draw::DrawList list;
  if (view.figure()) {
    // On white, as cpfg and ABOP draw them; no ground, no shadow.
    list.background = mesh::Vec3f(1, 1, 1);
    if (view.look == PlantLook::kLines) {
      list.lines.push_back(std::move(lines));
    } else {
      draw::MeshDraw& d = list.meshes.emplace_back();
      d.mesh = std::move(mesh);
      d.palette = palette;
      d.instances.emplace_back();
      d.castsShadow = false;
    }
  } else {
    // The plant on a ground plane, lit by the default rig; the shadow map
    // fitted to the whole plant, whatever was culled. No ground when the
    // camera looks from below it (it would hide everything), nor for a
    // cpfg object: cpfg draws none, and a ground would hide what hangs
    // below the base and fight with a base polygon drawn at it.
    list =
        scene::DefaultScene(std::move(mesh), palette, box.lo, box.hi,
                            !view.cpfgObject && scene::SeesGroundFromAbove(camera.Eye(), box.lo));
  }
  if (list.lights.empty()) list.lights = draw::DefaultLights();
  if (view.keyFromViewFile) list.lights[0].direction = -view.keyToward.cast<float>();
  return list;
}

}  // namespace sylva::app
