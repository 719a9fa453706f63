#include "app/cli.h"

#include <CLI/CLI.hpp>
#include <ostream>

#include "app/commands.h"
#include "app/viewer.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include "lsys/deriver.h"

namespace sylva::app {

int Report(const Diagnostic& d, std::ostream& err) {
  err << d.Format();
  if (d.severity != Severity::kError) return kExitOk;
  return d.kind == ErrorKind::kRuntime ? kExitRuntime : kExitBadInput;
}

int Report(const DiagnosticList& list, std::ostream& err, int maxErrors, bool strict) {
  err << list.FormatAll(size_t(maxErrors));
  int code = list.droppedErrors > 0 ? kExitBadInput : kExitOk;
  size_t warnings = 0;
  for (const auto& d : list.items) {
    if (d.severity != Severity::kError) {
      warnings += d.severity == Severity::kWarning;  // not notes
      continue;
    }
    int c = d.kind == ErrorKind::kRuntime ? kExitRuntime : kExitBadInput;
    if (c == kExitBadInput || code == kExitOk) code = c;
  }
  if (strict && warnings > 0) {
    err << "sylva: error: --strict: " << warnings
        << (warnings == 1 ? " warning is treated as an error\n"
                          : " warnings are treated as errors\n");
    code = kExitBadInput;
  }
  return code;
}

static void AddStrictFlag(CLI::App* cmd, bool& strict) {
  cmd->add_flag("--strict", strict,
                "treat every warning as an error (exit 2), e.g. a cpfg command Sylva does not "
                "implement");
}

static void AddMaxErrorsFlag(CLI::App* cmd, DeriveFlags& f) {
  cmd->add_option("--max-errors", f.maxErrors,
                  "print at most this many errors (and warnings), then a count of the rest "
                  "(default 20; 0: all)")
      ->check(CLI::Range(0, 1000000));
}

static void AddMaxTrianglesFlag(CLI::App* cmd, DeriveFlags& f) {
  cmd->add_option("--max-triangles", f.maxTriangles,
                  "stop with an error, before meshing, when the mesh would have more triangles "
                  "(default 67108864, about 2 GiB)")
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 32));
}

static void AddDeriveFlags(CLI::App* cmd, DeriveFlags& f) {
  cmd->add_option("file", f.file, "grammar file (.lsys)")->required();
  cmd->add_option("-n,--steps", f.steps, "derivation steps (default: the grammar's)")
      ->check(CLI::Range(0, lsys::kMaxDerivationLength));
  cmd->add_option("--seed", f.seed, "seed of the random numbers (default: the grammar's)");
  cmd->add_option("-D,--define", f.defines, "override a #define: NAME=VALUE (repeatable)");
  cmd->add_option("--threads", f.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(0, 256));
  cmd->add_option("--max-modules", f.maxModules,
                  "stop with an error when the word would grow past this many modules "
                  "(default 268435456)")
      ->check(CLI::Range(uint64_t(1), lsys::kMaxModulesCap));
  cmd->add_option("--view", f.view,
                  "cpfg view file (.v): angle, widths, colours, tropism, view direction "
                  "(default: NAME.v beside the grammar, if any)");
  AddMaxErrorsFlag(cmd, f);
  AddStrictFlag(cmd, f.strict);
}

static int NotBuilt(const char* command, std::ostream& err) {
  err << "sylva: error: this sylva was built without the " << command
      << " command (SYLVA_BUILD_RENDER / SYLVA_BUILD_VIEWER off)\n";
  return kExitBadInput;
}

// Replaces this process with sylva-graphics running the same arguments.
// Returns only on failure.
static int ExecGraphics(const std::vector<std::string>& args, std::ostream& out,
                        std::ostream& err) {
  std::string self(4096, '\0');
  const ssize_t n = readlink("/proc/self/exe", self.data(), self.size() - 1);
  self.resize(n > 0 ? size_t(n) : 0);
  const std::string dir =
      self.substr(0, self.rfind('/') == std::string::npos ? 0 : self.rfind('/'));
  const std::string candidates[] = {dir + "/sylva-graphics",
                                    dir + "/../libexec/sylva/sylva-graphics"};
  for (const std::string& path : candidates) {
    if (access(path.c_str(), X_OK) != 0) continue;
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(path.c_str()));
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    out.flush();
    err.flush();
    execv(path.c_str(), argv.data());
    err << "sylva: error: cannot run " << path << ": " << std::strerror(errno) << "\n";
    return kExitRuntime;
  }
  err << "sylva: error: the drawing commands are not installed: no sylva-graphics beside "
      << (self.empty() ? std::string("sylva") : self) << " or in ../libexec/sylva\n";
  return kExitBadInput;
}

int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
           const GraphicsCommands* graphics) {
  CLI::App app{"Sylva: L-system grammars and particle systems", "sylva"};
  app.require_subcommand(1, 1);
  app.set_version_flag("--version", "sylva 0.1.0");

  DeriveCommand derive;
  CLI::App* d = app.add_subcommand("derive", "derive a grammar and print the word or statistics");
  AddDeriveFlags(d, derive.derive);
  d->add_flag("--stats", derive.stats, "print statistics instead of the word");
  d->add_flag("--interpret", derive.interpret,
              "apply the interpretation rules (the word the turtle reads)");
  d->add_option("-o,--output", derive.output, "write the word to this file");

  MeshCommand mesh;
  CLI::App* me = app.add_subcommand(
      "mesh", "derive a grammar and write the plant mesh, or write a scene (.xml) as glTF");
  AddDeriveFlags(me, mesh.derive);
  me->add_option("-o,--output", mesh.output, "mesh file: .obj (+ .mtl), .ply, .glb or .gltf")
      ->required();
  me->add_option("--time", mesh.time,
                 "scenes: simulate this many seconds and write the particles then (default 0)")
      ->check(CLI::Range(0.0, 1e6));
  AddMaxTrianglesFlag(me, mesh.derive);
  CLI::Option* meSides =
      me->add_option("--sides", mesh.sides, "vertices around each branch tube (3-256, default 8)")
          ->check(CLI::Range(3, 256));
  me->add_option("--lod-eps", mesh.lodEps,
                 "screen-space detail for the view of --size and --camera: silhouette error in "
                 "pixels (docs/lod.md); default: uniform --sides")
      ->check(CLI::Range(1e-3, 1e6))
      ->excludes(meSides);
  me->add_option("--size", mesh.size, "with --lod-eps: image size WxH (default 960x540)");
  me->add_option("--camera", mesh.camera,
                 "with --lod-eps: azimuth,elevation,distance (as for render)");

  RenderCommand render;
  CLI::App* re = app.add_subcommand("render", "derive a grammar and render it to a PNG, headless");
  AddDeriveFlags(re, render.derive);
  re->add_option("-o,--output", render.output, "image file (.png, .jpg or .jpeg)")->required();
  re->add_option("--size", render.size, "image size WxH (default 960x540)");
  re->add_option("--time", render.time,
                 "scenes: simulate this many seconds before the picture (default 0)")
      ->check(CLI::Range(0.0, 1e6));
  re->add_option("--camera", render.camera,
                 "azimuth,elevation,distance in degrees and units (distance 0: frame the plant)");
  AddMaxTrianglesFlag(re, render.derive);
  CLI::Option* reEps = re->add_option(
      "--lod-eps", render.lodEps,
      "screen-space detail: silhouette error of the tubes in pixels (default 0.5; docs/lod.md)");
  reEps->check(CLI::Range(1e-3, 1e6));
  re->add_option("--sides", render.sides,
                 "uniform tubes of this many sides (3-256) instead of screen-space detail")
      ->check(CLI::Range(3, 256))
      ->excludes(reEps);
  re->add_option("--supersample", render.supersample,
                 "render K x K times larger and box-filter down (1-8, default 1)")
      ->check(CLI::Range(1, 8));
  re->add_flag("--stats", render.stats, "print `triangles: N` and the time of each stage");
  re->add_flag("--wireframe", render.wireframe, "draw the triangles' edges over the mesh");

  ViewCommand view;
  CLI::App* vi =
      app.add_subcommand("view", "open the interactive viewer (reloads the file when it changes)");
  vi->add_option("file", view.file,
                 "grammar file (.lsys) or scene file (.xml, played); default: the bundled "
                 "autumn scene");
  vi->add_option("--screenshot", view.screenshot,
                 "save this picture (.png, .jpg) after --frames frames and quit");
  vi->add_option("--frames", view.frames, "frames to draw before the screenshot")
      ->check(CLI::Range(1, 1000000));
  vi->add_option("--size", view.size, "window size WxH (default 1280x720)");
  vi->add_option("--orbit", view.orbit,
                 "turn the camera by this many degrees a frame (grammars; tests and demos)");
  AddStrictFlag(vi, view.strict);
  vi->add_option("--time", view.time, "scenes: start paused at this time in seconds")
      ->check(CLI::Range(0.0, 1e6));
  vi->add_option("-D,--define", view.defines,
                 "override a grammar's #define or a scene's <default>: NAME=VALUE (repeatable)");
  vi->add_option("--threads", view.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(0, 256));
  vi->add_option("-n,--steps", view.steps, "grammars: the derivation step to start at")
      ->check(CLI::Range(0, lsys::kMaxDerivationLength));
  vi->add_option("--seed", view.seed, "grammars: the seed to start with");
  vi->add_option("--view", view.view,
                 "grammars: cpfg view file (.v): angle, widths, colours, view direction, "
                 "projection, lights (default: NAME.v beside the grammar, if any)");

  DeriveFlags check;
  CLI::App* c = app.add_subcommand(
      "check", "parse and check a grammar or a scene (.xml, with its grammars); print diagnostics");
  c->add_option("file", check.file, "grammar file (.lsys) or scene file (.xml)")->required();
  c->add_option("-D,--define", check.defines,
                "override a grammar's #define or a scene's <default>: NAME=VALUE (repeatable)");
  c->add_option("--view", check.view,
                "grammars: cpfg view file (.v) to check with it (default: NAME.v beside it)");
  AddMaxErrorsFlag(c, check);
  AddStrictFlag(c, check.strict);

  SimulateCommand simulate;
  CLI::App* si = app.add_subcommand(
      "simulate", "run a scene's simulation: frames as images (-o), the final state as CSV");
  si->add_option("file", simulate.file, "scene file (.xml)")->required();
  si->add_option("-o,--output", simulate.output,
                 "frame images, a pattern with one %d: frames/%04d.png (none without -o)");
  si->add_option("--duration", simulate.duration,
                 "simulated seconds (default: the scene's <simulation duration>)")
      ->check(CLI::Range(0.0, 1e6));
  si->add_option("--fps", simulate.fps, "frames written a second (default: the scene's fps)")
      ->check(CLI::Range(1e-3, 1000.0));
  si->add_option("--dump", simulate.dump,
                 "write every particle, cloth vertex and boid at the end as CSV");
  si->add_option("--size", simulate.size, "frame size WxH (default 960x540)");
  si->add_option("-D,--define", simulate.defines, "override a scene's <default>: NAME=VALUE");
  si->add_option("--threads", simulate.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(0, 256));
  si->add_option("--max-errors", simulate.maxErrors, "print at most this many errors")
      ->check(CLI::Range(0, 1000000));
  AddStrictFlag(si, simulate.strict);

  std::vector<std::string> rev(args.rbegin(), args.rend());
  try {
    app.parse(rev);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {
      // app.help() is the selected subcommand's help when one is given
      // (`sylva view --help`), printed once.
      out << (e.get_name() == "CallForVersion" ? std::string(e.what()) + "\n" : app.help());
      return kExitOk;
    }
    err << "sylva: error: " << e.what() << "\n";
    err << "run 'sylva --help' for usage\n";
    return kExitBadInput;
  }
  // The command boundary: nothing escapes as an exception (memory
  // exhaustion in a library, a file system error), and output that could
  // not be written is an error, not exit 0.
  int code = kExitBadInput;
  try {
    if (d->parsed()) code = RunDerive(derive, out, err);
    if (c->parsed()) code = RunCheck(check, out, err);
    if (me->parsed() && !mesh.lodEps) code = RunMesh(mesh, out, err);
    if (si->parsed() && simulate.output.empty()) code = RunSimulate(simulate, out, err, {});
    if (re->parsed() || vi->parsed() || (si->parsed() && !simulate.output.empty()) ||
        (me->parsed() && mesh.lodEps)) {
      if (!view.screenshot.empty() && view.frames == 0) view.frames = 3;
      const GraphicsCommands none;
      const GraphicsCommands& g = graphics ? *graphics : none;
      if (g.execGraphicsBinary) return ExecGraphics(args, out, err);
      if (re->parsed()) code = g.render ? g.render(render, out, err) : NotBuilt("render", err);
      if (vi->parsed()) code = g.view ? g.view(view, out, err) : NotBuilt("view", err);
      if (me->parsed()) {
        code = g.meshForView ? g.meshForView(mesh, out, err) : NotBuilt("mesh --lod-eps", err);
      }
      if (si->parsed())
        code = g.simulate ? g.simulate(simulate, out, err) : NotBuilt("simulate -o", err);
    }
  } catch (const std::bad_alloc&) {
    err << "sylva: error: out of memory; for a grammar, lower the derivation length (-n), the "
           "detail or the limits; for a scene, lower its counts, resolutions and steps\n";
    code = kExitRuntime;
  } catch (const std::exception& e) {
    err << "sylva: error: " << e.what() << "\n";
    code = kExitRuntime;
  }
  out.flush();
  if (!out) {
    err << "sylva: error: cannot write to standard output\n";
    if (code == kExitOk) code = kExitRuntime;
  }
  err.flush();
  if (!err && code == kExitOk) code = kExitRuntime;
  return code;
}

}  // namespace sylva::app
