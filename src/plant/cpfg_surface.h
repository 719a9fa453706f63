// cpfg's surface files (`.s`): bicubic Bezier patches, read into the mesh
// a `~l` places.
//
// A cpfg view file names a surface by one letter: `surface: l leaf.s 800 3 5`
// (letter, file, size, s and t precision). `~l(s)` then draws leaf.s at the
// turtle, its contact point on the turtle's position, its heading and up
// along the turtle's, and its largest dimension (the file's SIZE) scaled to
// the view file's size times s.
//
// The format, as vlab's cpfg reads it (src/cpfg/patch.c, read_patch_file and
// get_patch):
//
//   xmin xmax  ymin ymax  zmin zmax                (bounding box; skipped)
//   PRECISION S: 5 T: 5                            (optional)
//   CONTACT POINT  X: 0.0 Y: 0.0 Z: 370.0
//   END POINT  X: 0.0 Y: 0.0 Z: -0.46              (skipped)
//   HEADING  X: 0.0 Y: 0.0 Z: -1.0
//   UP  X: 0.0 Y: -1.0 Z: 0.0
//   SIZE: 301.38
//   then per patch: a name line, `TOP COLOR: ...` (skipped: the turtle's
//   colour is used), three lines of neighbour names (skipped), and 16
//   control points `x y z`, four rows of four.
//
// Each patch is evaluated as a bicubic Bezier patch on a grid of
// max(precision, kMinPatchDivisions) steps a side, so the coarse precisions
// cpfg files give (2 to 5) still look smooth. A point p of the file lands at
// (p - contact) * size / SIZE, expressed in the frame (left, heading, up)
// with left = heading x up (the file's up made perpendicular to its
// heading), which is the surface's own (x, y, z) = the turtle's (L, H, U).
// Both sides are drawn (one triangle each way), as cpfg draws patches.
#pragma once

#include <string>

#include "core/status.h"
#include "mesh/triangle_mesh.h"

namespace sylva::plant {

inline constexpr int kMinPatchDivisions = 8;

// What the view file's `surface:` line says (and where, for diagnostics).
struct CpfgSurfaceDef {
  std::string name;    // the one letter of `~l`
  std::string file;    // the .s file, resolved against the view file's folder
  double size = 1;     // the largest dimension of the surface, before ~l(s)
  int sPrecision = 0;  // subdivisions a patch side; 0: the file's or the minimum
  int tPrecision = 0;
  std::string viewFile;  // where the line is, for diagnostics
  int line = 0;
  // The file does not exist (the view file reader warned): `~l` draws
  // nothing instead of failing.
  bool missing = false;
};

// Reads a .s file's text into a mesh in the surface's own frame. Errors (a
// missing or unreadable header line, a heading of zero length, a patch with
// fewer than 16 points, a non-finite number) carry `path` and the line.
Expected<mesh::TriangleMesh> ParseCpfgSurface(const std::string& text, const std::string& path,
                                              double size, int sPrecision = 0, int tPrecision = 0);

}  // namespace sylva::plant
