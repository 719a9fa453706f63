// How `sylva render` and `sylva view` show the plant of one grammar: the
// look (lit mesh, lines, or pixel-wide ribbons), the projection, the
// direction the camera looks from and how it frames the plant, the lights,
// the ground and the screen-space detail. One set of rules for both, so
// the viewer's first frame is render's picture of the same file.
//
// The rules, in order:
//  - a 2D figure (plant::IsLineFigure) draws as one-pixel lines on white,
//    or, when its widths are pixels (a cpfg view file's line style) and
//    some are wider than one, as ribbons of those widths on white; no
//    ground, no shadow; orthographic;
//  - the camera looks from --camera (render), else from the view file's
//    viewpoint (`viewpoint:`, `view reference point:`), else from cpfg's
//    default viewpoint 0,0,1 for a `.l` without a view file, else from +Z
//    for a 2D figure, else from azimuth 30, elevation 12;
//  - orthographic for 2D figures, for `projection: parallel` (cpfg's
//    default in a view file) and for a `.l` without a view file (cpfg's
//    default view); else perspective, of the view file's `viewing angle:`
//    (35 degrees by default);
//  - the framed view is zoomed by the view file's `scale factor:` (not
//    under --camera);
//  - the key light (the shadow caster) shines from the view file's light
//    (ViewFile::lightToward) when it gives one;
//  - a cpfg object (a view file, or a `.l` in cpfg's default view) stands
//    on no ground, as cpfg draws none; nor does a plant seen from below
//    its base.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "app/view_file.h"
#include "core/math.h"
#include "draw/draw_list.h"
#include "mesh/screen_detail.h"
#include "mesh/triangle_mesh.h"
#include "plant/plant.h"
#include "render/camera.h"

namespace sylva::app {

enum class PlantLook {
  kMesh,     // a lit mesh in the default scene
  kLines,    // a 2D figure: one-pixel lines on white
  kRibbons,  // a 2D figure whose pixel widths exceed one: ribbons on white
};

struct PlantView {
  PlantLook look = PlantLook::kMesh;
  bool orthographic = false;
  bool cpfgObject = false;  // a view file or cpfg's default view: no ground
  // The direction the camera looks from (render::Camera's degrees).
  double azimuth = 30, elevation = 12;
  double distance = 0;                 // > 0: --camera's distance; 0: framed
  bool cameraFlag = false;             // --camera given: the view file's zoom is not applied
  std::optional<double> scale;         // `scale factor:`
  std::optional<double> viewingAngle;  // `viewing angle:` (perspective)
  // cpfg's perspective camera (control.c, SetView), which frames nothing:
  // looking at the view reference point from `distance` (|viewpoint - vrp|
  // / scale factor) with a field of view of `viewing angle:` (45 degrees by
  // default). Set when a perspective view file gives a viewpoint or a
  // reference point; 0: the box is framed.
  Vec3 cpfgTarget = Vec3::Zero();
  double cpfgDistance = 0;
  // cpfg's `box:`: the view volume a parallel view frames (CalculateWindow)
  // in place of the plant's box.
  std::optional<std::array<Vec3, 2>> viewBox;
  Vec3 keyToward = Vec3::UnitY();  // unit, toward the key light
  bool keyFromViewFile = false;    // keyToward is the view file's light

  bool figure() const { return look != PlantLook::kMesh; }
};

// The view of a plant of `grammarPath`, built to its geometry (`geometry`
// null: as a mesh, for `sylva mesh --lod-eps`), with its view file (null
// when none) and --camera's azimuth, elevation, distance (null when not
// given).
PlantView ChoosePlantView(const std::string& grammarPath, const ViewFile* view,
                          const mesh::PlantGeometry* geometry, const double* camera = nullptr);

// The box a view frames: the geometry's for a 2D figure, else the mesh's
// (plant::MeshBounds, before tessellation, so every detail sees one view).
// An empty box (nothing drawn) is the unit box.
Expected<mesh::Box> FramedBox(const PlantView& view, const plant::Plant& plant,
                              const plant::PlantSpec& spec);

// The camera `sylva render` takes, and `sylva view` starts from: the box
// framed from the view's direction, its projection, its zoom.
render::Camera FramePlant(const PlantView& view, const mesh::Box& box, double aspect);

// Whether any of `box` lies inside the camera's view (its frustum at
// `aspect`): false when all eight corners are beyond one clip plane, as for
// a cpfg perspective camera that looks away from the plant or a `box:`
// that holds none of it (the picture would be empty).
bool SeesBox(const render::Camera& camera, double aspect, const mesh::Box& box);

// Whether any primitive of `g` may show in the camera's view (at
// `aspect`): one whose bounding box lies wholly beyond one clip plane does
// not. Conservative: a primitive that only crosses a corner of the view
// counts as seen, and so does a surface (`~`), whose size is its file's.
bool SeesAnyOf(const render::Camera& camera, double aspect, const mesh::PlantGeometry& g);

// A warning at the view file's camera line when the camera does not frame
// the plant (cpfg's perspective camera, a parallel view's `box:`) and sees
// none of its geometry `g` (whose bounds are `box`): `sylva render` would
// write an empty picture. Nullopt when the camera sees some of it, frames
// it, or the plant draws nothing at all.
std::optional<Diagnostic> UnseenPlantWarning(const PlantView& view, const ViewFile* viewFile,
                                             const render::Camera& camera, double aspect,
                                             const mesh::Box& box, const mesh::PlantGeometry& g);

// The box framed from another direction, in the view's projection at the
// view's field of view, without the view file's zoom (everything shows):
// the viewer's "frame all".
render::Camera FrameAll(const PlantView& view, const mesh::Box& box, double aspect, double azimuth,
                        double elevation);

// The screen-space view a mesh is tessellated for: the camera's view at
// width x height, `eps` pixels; shadows of what lies outside the view kept
// (the key light's, its map `shadowTexelsScale` times the default texels per
// unit); coverage lines; a 2D figure's pixel-wide ribbons never tubes.
mesh::ScreenView ScreenViewFor(const PlantView& view, const render::Camera& camera, int width,
                               int height, double eps, const mesh::Box& box,
                               double shadowTexelsScale, const mesh::PlantGeometry& geometry);

// The frame to draw: a 2D figure's `lines` (PlantLook::kLines) or `mesh`
// (ribbons, or the plant in the default scene: ground unless a cpfg object
// or seen from below, the key light turned to the view's).
draw::DrawList PlantScene(const PlantView& view, std::shared_ptr<const mesh::TriangleMesh> mesh,
                          const mesh::Palette& palette, draw::Lines lines, const mesh::Box& box,
                          const render::Camera& camera);

// Whether a geometry's widths are pixels and some are wider than the one
// pixel of a line.
bool WiderThanAPixel(const mesh::PlantGeometry& g);

}  // namespace sylva::app
