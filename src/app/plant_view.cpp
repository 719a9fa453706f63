// How render and the viewer show a grammar's plant: see plant_view.h.
#include "app/plant_view.h"

#include <algorithm>
#include <cmath>
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
