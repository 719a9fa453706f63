// cpfg's background scene: a view file's `background scene: FILE` names a
// text file of primitives that cpfg draws behind the plant on every redraw
// (vlab cpfg/background.c, Mech 1995). Sylva reads it and adds its
// primitives to the plant's geometry, so `render` and `view` draw them
// with the plant (and frame them with it).
//
// The file (run through cpfg's preprocessor: `#define NAME value`, /* */
// and // comments) is a sequence of keywords, each followed by its numbers:
//   material a a a a  d d d d  [s s s s  [e e e e  [shininess]]]
//                                 ambient, diffuse, specular, emissive RGBA;
//                                 what follows takes the diffuse colour
//   polygon x y z  x y z  x y z ...           a polygon of 3 or more points
//   polygonuv x y z nx ny nz ...              the same with normals (read, not used)
//   rectangle w h [x y [emission]]            w by h in the z = 0 plane from (x, y)
//   mesh x y z x y z  x y z x y z ...         rows of two points: quads between rows
//   prism x y z   (or box x y z)              the box from the origin to (x, y, z)
//   cylinder r h                              radius r from the origin to y = h, capped
//   cone r1 r2 h                              radius r1 at y = 0 to r2 at y = h, capped
//   sphere r                                  a sphere of radius r at the origin
//   pushmatrix  popmatrix  translate x y z  rotate angle x y z  scale x y z
//   multmatrix m0 .. m15                      (OpenGL's order: the translation
//                                              is m12 m13 m14)
// Each primitive goes through the current matrix, as cpfg's own matrix
// stack places it. As in cpfg, a sphere, cylinder or cone takes its
// position and axis from the matrix but not its size (scale does not
// change its radius). What Sylva draws differently: translucent materials
// (an alpha below 1) are drawn opaque, with a warning at the first; only
// the diffuse colour is used.
//
// Errors (a diagnostic at the file's line and column): an unknown keyword,
// a primitive with too few numbers, a `popmatrix` without its
// `pushmatrix`, a preprocessor line other than #define and #undef, a
// primitive placed at a point that is not finite or beyond +-1e15 (as the
// turtle's), a sphere radius that is not finite, and the limits below (a
// #define used many times, or a file of many cylinders, would otherwise
// take more memory than the machine has).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "core/math.h"
#include "core/status.h"
#include "mesh/export.h"
#include "mesh/plant_geometry.h"

namespace sylva::app {

// Words after #define substitution (a 16 MiB file holds at most 8M words
// without #defines), vertices of the primitives, and materials.
inline constexpr size_t kMaxBackgroundWords = size_t(8) << 20;
inline constexpr size_t kMaxBackgroundVertices = size_t(4) << 20;
inline constexpr size_t kMaxBackgroundMaterials = 32768;

struct BackgroundScene {
  std::string path;
  std::vector<mesh::Polygon> polygons;       // colour: index into `colors` + 1, or 0 (palette 0)
  std::vector<mesh::Sphere> spheres;         // the same
  std::vector<std::array<float, 3>> colors;  // sRGB 0..1: the diffuse colour of each `material`
};

// Reads a background scene's text; `path` names it in diagnostics, and
// warnings (translucent materials) go to `warnings`.
Expected<BackgroundScene> ParseBackgroundScene(const std::string& text, const std::string& path,
                                               DiagnosticList& warnings);

// Adds the scene's primitives to `geometry` (its bounds grow to hold them;
// it is no longer planar) and their colours to `palette`, after the
// entries it has.
void AddBackgroundScene(const BackgroundScene& scene, mesh::PlantGeometry& geometry,
                        mesh::Palette& palette);

}  // namespace sylva::app
