// cpfg's view file (`.v`), colour map (`.map`) and material (`.mat`) files.
//
// cpfg takes from them what a Sylva grammar writes in its header: the angle
// increment, the initial line width and its increment, the initial colour
// index and its increment, the tropism, and the colours. `sylva render
// plant.l` (mesh, check, derive, view) reads `plant.v` beside the grammar,
// or the file `--view FILE` names, and `plant.map` / `plant.mat` beside the
// grammar or the view file (the .mat wins when both exist).
//
// The reference is vlab's cpfg (src/cpfg/interpret.c, ReadViewData; irisGL.c,
// load_in_colormaps and load_in_materials):
//   .v    one setting a line, `label: values`; labels as in cpfg's manual.
//   .map  256 colours of 3 bytes (r, g, b), 768 bytes, colour index i is
//         entry i.
//   .mat  records of 15 bytes: the colour index, then transparency,
//         ambient rgb, diffuse rgb, emissive rgb, specular rgb, shininess;
//         Sylva takes the diffuse colour.
//
// Nothing is silently ignored: every line Sylva does not act on is a warning
// at its file:line:col (`--strict` makes it an error); a value that cannot be
// read, and a file that is not a readable regular file of a sane size
// (truncated, huge, a directory, a device), is an error.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/cpfg_background.h"
#include "core/diagnostic.h"
#include "core/math.h"
#include "lsys/grammar.h"
#include "lsys/parser.h"
#include "plant/frames.h"
#include "plant/plant.h"
#include "turtle/interpreter.h"

namespace sylva::app {

// What a view file (and its colour files) says that Sylva acts on; unset:
// the file does not say it.
struct ViewFile {
  std::string path;                           // the view file read; empty when there was none
  std::optional<double> angle;                // `angle increment:` or 360 / `angle factor:`
  std::optional<double> width;                // `initial line width:`
  std::optional<double> widthIncrement;       // `line width increment:`
  std::optional<int> initialColor;            // `initial color:`
  std::optional<int> colorIncrement;          // `color increment:`
  std::optional<Vec3> tropism;                // `tropism direction:` (unit; 0 for 0,0,0)
  std::optional<double> elasticity;           // `initial elasticity:` (cpfg's older tropism)
  std::optional<double> elasticityIncrement;  // `elasticity increment:` (its `_` step)
  std::optional<Vec3> viewpoint;              // `viewpoint:` (the eye)
  std::optional<Vec3> target;                 // `view reference point:`
  // The line that places cpfg's camera: `viewpoint:`, else `view reference
  // point:` (0: neither); warnings about what that camera sees point there.
  int cameraLine = 0;
  std::optional<double> scale;         // `scale factor:` (> 0)
  std::optional<double> viewingAngle;  // `viewing angle:` (degrees, 0..180): perspective
  // cpfg's newer tropisms and torques: the `tropism:` and `torque:` lines in
  // order (at most lsys::kMaxMovements); @Ts @Ti @Td(i, ...) address them.
  std::vector<lsys::Movement> movements;
  // `box: x: x0,x1 y: y0,y1 z: z0,z1`: cpfg's fixed view volume, framed by
  // a parallel view instead of the plant's bounds (low corner, high corner).
  std::optional<std::array<Vec3, 2>> box;
  int boxLine = 0;  // its line
  // cpfg's line style: widths in pixels on the screen (`initial line
  // width: 2 pixels`, `line style: pixel`, or neither: cpfg's default,
  // with a width of 1), not in world units (`initial line width: 0.1`,
  // `... 0.1 s`, `line style: polygon` or `cylinder`). False without a
  // view file.
  bool widthInPixels = false;
  // cpfg's projection: parallel (`projection: parallel`, and cpfg's
  // default when the line is missing) or perspective. False without a
  // view file.
  bool parallel = false;
  // Unit direction toward cpfg's light: the first `light:` line's V (or
  // its O position seen from the origin), else `light direction:`; it
  // turns the key light of `sylva render`.
  std::optional<Vec3> lightToward;
  // cpfg's animation file NAME.a beside the grammar, when it says `clear
  // between frames: off` and `double buffer: off`: cpfg's picture is then
  // the frames from `first frame:` to `last frame:` (every `step:`) drawn
  // over each other (plant/frames.h). Its other lines are playback settings that do not
  // change a still picture, and are not read.
  std::string animationPath;
  std::optional<plant::FrameRange> overlay;
  std::string colorsPath;                       // the .map or .mat read
  std::vector<std::array<float, 3>> palette;    // sRGB 0..1 of each colour index
  std::vector<plant::CpfgSurfaceDef> surfaces;  // `surface: l leaf.s size s t`
  // `function: FILE.func [samples]` and `function set: FILE.fset`, in order
  // (func(1, x) the first).
  std::vector<lsys::ParseOptions::FunctionFile> functions;
  // Generalized-cylinder contours for @#(n): `contour: n FILE.con` (the
  // files read when the view file's files are checked; a missing one is a
  // warning and @#(n) draws round), `contour sides: S`, `twist of
  // cylinders: on|off`. cpfg draws them with its line style cylinder only
  // (`line style: cylinder`, or `initial line width: W s...`).
  turtle::CylinderContours contours;
  bool cylinderStyle = false;
  // `curve: FILE.con [samples]`, in order (curveX(1, t) the first).
  std::vector<lsys::ParseOptions::CurveFile> curves;
  // `background scene: FILE[,FILE...]`: the files, resolved, with the
  // line and column that name them; LoadViewFiles reads them into
  // `backgrounds` (app/cpfg_background.h), drawn with the plant.
  struct NamedFile {
    std::string file;
    int line = 0, column = 0;
  };
  std::vector<NamedFile> backgroundFiles;
  std::vector<std::shared_ptr<const BackgroundScene>> backgrounds;
  DiagnosticList diagnostics;  // warnings, and errors that stop the build
};

// Reads the text of a view file; `path` names it in diagnostics. With
// checkFiles, a `surface:` file that does not exist is a warning at its
// name ("surface 'c' is not drawn") and the surface draws nothing
// (CpfgSurfaceDef::missing): a folder copied without one of its .s files
// still opens; --strict makes it an error.
ViewFile ParseViewFile(const std::string& text, const std::string& path, bool checkFiles = false);

// 768 bytes of a .map: 256 sRGB colours. An error when shorter; a warning
// (in `warnings`) when longer: only the first 768 bytes are colours.
Expected<std::vector<std::array<float, 3>>> ParseColormap(const std::string& bytes,
                                                          const std::string& path,
                                                          DiagnosticList& warnings);

// Records of a .mat: 256 colours, the diffuse colour of each material
// (indices without a material: light grey, cpfg's default). An error when
// the size is not a whole number of records.
Expected<std::vector<std::array<float, 3>>> ParseMaterials(const std::string& bytes,
                                                           const std::string& path);

// The view file and colours of the grammar at `grammarPath`: `explicitView`
// when not empty (an error when it cannot be read), else NAME.v beside the
// grammar if it exists, else the view file the object's cpfg command names
// in vlab's `specifications` beside the grammar (app/cpfg_specifications.h;
// `cpfg -M materials.mat lamp.l view.v`), whose -M/-m colour files then come
// first; then NAME.mat or NAME.map beside the grammar or the view file;
// NAME.a beside the grammar. A file the command names that is missing is a
// warning. nullptr when there is none of them and nothing to say.
std::shared_ptr<const ViewFile> LoadViewFiles(const std::string& grammarPath,
                                              const std::string& explicitView);

// Reads an animation file's text into view.animationPath and view.overlay
// (errors and warnings to view.diagnostics).
void ParseAnimationFile(const std::string& text, const std::string& path, ViewFile& view);

// Puts what the view file says into the grammar (its header values, read
// as the turtle's defaults).
void ApplyViewFile(const ViewFile& view, lsys::Grammar& grammar);

// Sets spec.cpfgSurfaces, spec.cpfgFunctions and spec.cpfgCurves (the
// view's `surface:`, `function:` and `curve:` lines), spec.draw.contours
// (its contours, with line style cylinder: then even none, so that @#(n)
// names what is missing), spec.amendGeometry (its background scenes drawn
// with the plant) and
// spec.amendGrammar: the view applied and its diagnostics added to the
// plant's (so --strict counts them).
void AttachViewFile(std::shared_ptr<const ViewFile> view, plant::PlantSpec& spec);

// Azimuth and elevation in degrees (render::Camera's) of the direction from
// the view reference point to the viewpoint; nullopt when the file sets
// neither or they coincide. Elevation within -89..89.
std::optional<std::array<double, 2>> ViewDirection(const ViewFile& view);

}  // namespace sylva::app
