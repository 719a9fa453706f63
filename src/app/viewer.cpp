// The viewer. Threads: the UI thread owns the window, ImGui and every GL
// call; one worker derives, draws and tessellates jobs posted by the UI and
// hands back meshes. Only the newest job matters: a job that is overtaken
// is dropped when it finishes. Every job carries the whole request (file,
// defines, seed, step, detail, view); the worker keeps the last plant and
// only re-tessellates it when a job differs from it in the view or the
// detail alone (a camera move).
#include "app/viewer.h"

#include <GL/glew.h>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "app/cli.h"
#include "app/commands.h"
#include "app/define_sliders.h"
#include "app/plant_view.h"
#include "app/view_file.h"
#include "app/viewer_window.h"
#include "plant/frames.h"
#include "plant/plant.h"
#include "plant/surface_library.h"
#include "render/camera.h"
#include "render/renderer.h"

namespace sylva::app {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The viewer's shadow map (Renderer::SetShadowMapSize): smaller than
// `sylva render`'s, for cheaper shadow samples.
constexpr int kViewerShadowMapSize = 2048;
// A re-tessellated mesh goes to the GPU at most this many bytes a frame
// (Renderer::Stage), so its upload never stalls one frame.
constexpr size_t kUploadBytesPerFrame = size_t(8) << 20;

struct Job {
  uint64_t id = 0;
  std::string path;
  std::string viewPath;  // --view: the cpfg view file; empty: NAME.v beside the grammar
  uint64_t reload = 0;   // bumped when the file changes: the plant is rebuilt
  std::map<std::string, double> overrides;
  std::optional<uint64_t> seed;
  int steps = -1;
  int sides = 8;    // uniform detail, when lod is off
  bool lod = true;  // screen-space detail for the camera (docs/lod.md)
  int threads = 0;
  bool strict = false;  // warnings are errors
  // The view to tessellate for (with lod); empty: the framing of `sylva render`.
  std::optional<render::Camera> camera;
  int width = 1280, height = 720;
};

// Jobs that differ only in the view (or the detail) reuse the plant.
bool SamePlant(const Job& a, const Job& b) {
  return a.path == b.path && a.viewPath == b.viewPath && a.reload == b.reload &&
         a.overrides == b.overrides && a.seed == b.seed && a.steps == b.steps &&
         a.threads == b.threads && a.strict == b.strict;
}

struct Result {
  uint64_t id = 0;
  bool ok = false;
  bool rebuilt = false;     // a new plant, not only a new tessellation
  bool stale = false;       // the last good plant: the request's own failed to build
  uint64_t failedId = 0;    // with !ok or stale: the job whose build failed
  std::string diagnostics;  // errors and warnings, formatted
  mesh::TriangleMesh mesh;  // moved into the drawn scene when shown
  size_t triangles = 0;
  mesh::Palette palette;
  render::Camera camera;  // the view it was tessellated for
  // How render shows this plant (app/plant_view.h): the look, projection,
  // direction, framing and lights the viewer starts from.
  PlantView view;
  mesh::Box box{Vec3::Zero(), Vec3::Ones()};  // the framed box (ground and shadows fit it)
  bool pixelWidths = false;          // widths in pixels: re-tessellated for each view, lod or not
  std::vector<std::string> watched;  // the view file and its colour files (reloads)
  uint64_t modules = 0;
  int derivationLength = 0;
  std::vector<std::pair<std::string, double>> constants;  // file order not kept: sorted
  std::set<std::string> overridden;  // the constants the job set (the others are the file's)
  // A 2D figure drawn as lines (PlantLook::kLines): its lines.
  draw::Lines lines;
  double deriveMs = 0, turtleMs = 0, tessellateMs = 0;
};

// What the worker keeps between jobs: the last plant (geometry, before
// tessellation) and the detail history of its chains, so a camera move
// only re-tessellates, with hysteresis.
// A request whose plant failed to build is not built again for a camera
// move: the last good plant is re-tessellated, marked stale.
struct WorkerState {
  std::optional<Job> built;
  std::optional<plant::Plant> plant;
  plant::PlantSpec spec;
  mesh::Box bounds;
  PlantView view;
  std::vector<std::string> watched;
  std::string diagnostics;
  std::optional<Job> failed;
  std::string failedDiagnostics;
  mesh::DetailHistory history;
};

Result RunJob(const Job& job, WorkerState& st) {
  Result r;
  r.id = job.id;
  const bool failedBefore = st.failed && SamePlant(*st.failed, job);
  if (!failedBefore && (!st.plant || !st.built || !SamePlant(*st.built, job))) {
    plant::PlantSpec spec;
    spec.path = job.path;
    spec.defines = job.overrides;
    spec.seed = job.seed;
    if (job.steps >= 0) spec.steps = job.steps;
    spec.threads = job.threads;
    // cpfg's NAME.v (or --view's file, and .map, .mat) beside the grammar,
    // read again on each reload.
    const std::shared_ptr<const ViewFile> viewFile = LoadViewFiles(job.path, job.viewPath);
    AttachViewFile(viewFile, spec);
    spec.until = plant::Stage::kGeometry;
    plant::PlantResult built = plant::BuildPlant(spec);
    std::string diagnostics = built.diagnostics.FormatAll();
    std::optional<mesh::Box> bounds;
    PlantView view;
    if (built.plant && viewFile && viewFile->overlay) {
      // cpfg's animation file draws its frames over each other, as render does.
      DiagnosticList again;
      auto frames = plant::DrawFrames(spec, *viewFile->overlay, again);
      if (frames)
        built.plant->geometry = std::move(*frames);
      else
        diagnostics += frames.error().Format();
    }
    if (built.plant && job.strict && !built.diagnostics.items.empty()) {
      diagnostics += "sylva: error: --strict: warnings are treated as errors\n";
    } else if (built.plant) {
      view = ChoosePlantView(job.path, viewFile.get(), &built.plant->geometry);
      auto b = FramedBox(view, *built.plant, spec);
      if (b) bounds = *b;
      if (!b) diagnostics += b.error().message + "\n";
    }
    if (!bounds) {
      st.failed = job;
      st.failedDiagnostics = diagnostics;
      r.diagnostics = diagnostics;
      r.failedId = job.id;
      return r;
    }
    st.failed.reset();
    st.history = {};
    st.diagnostics = diagnostics;
    st.bounds = *bounds;
    st.view = view;
    st.watched.clear();
    if (viewFile)
      for (const std::string& f : {viewFile->path, viewFile->colorsPath, viewFile->animationPath})
        if (!f.empty()) st.watched.push_back(f);
    st.plant = std::move(built.plant);
    st.spec = spec;
    st.built = job;
    r.rebuilt = true;
  }
  if (failedBefore) r.failedId = st.failed->id;
  if (!st.plant) {
    r.diagnostics = st.failedDiagnostics;
    return r;
  }
  r.stale = failedBefore;
  r.diagnostics = failedBefore ? st.failedDiagnostics : st.diagnostics;
  plant::Plant& p = *st.plant;
  const double aspect = double(job.width) / job.height;
  r.camera = job.camera ? *job.camera : FramePlant(st.view, st.bounds, aspect);
  r.pixelWidths = p.geometry.widthInPixels;
  if (st.view.look == PlantLook::kLines) {
    r.lines = LinesOf(p);
  } else {
    plant::PlantSpec spec = st.spec;
    spec.detail.sides = job.sides;
    // Pixel widths need the view even at uniform detail (mesh/pixel_widths.h).
    if (job.lod || r.pixelWidths) {
      // The viewer's shadow map is smaller than `sylva render`'s.
      spec.view = ScreenViewFor(
          st.view, r.camera, job.width, job.height, 0.5, st.bounds,
          double(kViewerShadowMapSize) / render::Renderer::kDefaultShadowMapSize, p.geometry);
    }
    if (job.lod) {
      spec.history = &st.history;
    } else {
      st.history = {};  // levels of another detail mean nothing to the next view
    }
    DiagnosticList warnings;
    if (Status s = plant::Tessellate(p, spec, warnings); !s.ok()) {
      r.diagnostics += s.error().message + "\n";
      return r;
    }
    r.mesh = std::move(p.mesh);
    p.mesh = mesh::TriangleMesh();
  }
  r.derivationLength = p.grammar.derivationLength;
  for (const auto& [k, v] : p.grammar.constants) r.constants.emplace_back(k, v);
  std::sort(r.constants.begin(), r.constants.end());
  for (const auto& [k, v] : st.built->overrides) r.overridden.insert(k);
  r.palette = p.palette;
  r.modules = p.DrawnWord().size();
  r.triangles = r.mesh.triangleCount();
  r.view = st.view;
  r.box = st.bounds;
  r.watched = st.watched;
  r.deriveMs = p.time.parse + p.time.derive + p.time.interpret;
  r.turtleMs = p.time.turtle;
  r.tessellateMs = p.time.tessellate;
  r.ok = true;
  return r;
}

// The camera has moved far enough from the one the shown mesh was
// tessellated for to re-tessellate: 5 % nearer or farther (or zoomed in or
// out by 5 % in parallel projection), 2 degrees around, the target 2 % of
// the distance away, or another projection.
bool MovedFarEnough(const render::Camera& a, const render::Camera& b) {
  return a.orthographic != b.orthographic || std::abs(std::log(a.distance / b.distance)) > 0.05 ||
         (a.orthographic && std::abs(std::log(a.orthoHeight / b.orthoHeight)) > 0.05) ||
         std::abs(a.azimuth - b.azimuth) > 2 || std::abs(a.elevation - b.elevation) > 2 ||
         (a.target - b.target).norm() > 0.02 * a.distance || a.fovY != b.fovY;
}

// A live edit can ask for anything (a word or mesh larger than memory): the
// worker reports it as a failed job and the viewer keeps the last plant.
Result RunJobSafely(const Job& job, WorkerState& state) {
  try {
    return RunJob(job, state);
  } catch (const std::bad_alloc&) {
    Result r;
    r.id = job.id;
    r.diagnostics =
        job.path + ": error: out of memory building the plant; lower the step or the detail\n";
    return r;
  } catch (const std::exception& e) {
    Result r;
    r.id = job.id;
    r.diagnostics = job.path + ": error: " + e.what() + "\n";
    return r;
  }
}

// With no file: the bundled autumn scene (SCENE.md: `sylva view` with no
// argument opens one of the example scenes), or the ABOP tree where the
// examples are not installed.
std::string DefaultGrammar() {
  const fs::path data = plant::BundledDataDir();
  std::error_code ec;
  const fs::path scene = data / "examples" / "scenes" / "autumn.xml";
  if (fs::is_regular_file(scene, ec)) return scene.string();
  return (data / "grammars" / "abop" / "fig2_06a_monopodial.lsys").string();
}

// What the panel shows of the newest results.
struct Shown {
  std::optional<Result> plant;  // the last good plant
  uint64_t id = 0;              // the job it came from
  std::string diagnostics;
  bool lastFailed = false;
  std::vector<std::pair<std::string, double>> constants;
  // Each #define's slider range, fixed: set from the file's value (not from
  // a value the slider set, or the range would follow the slider away).
  std::map<std::string, SliderRange> ranges;
  int derivationLength = 0;
  bool playing = false;  // stepping the derivation 0, 1, 2 ... by itself
  Clock::time_point lastPlayed;
};

// What the panel asked for beyond a new job.
struct PanelActions {
  bool changed = false;   // post the job
  bool frameAll = false;  // frame the plant again
};

// The control panel: step (with play, step and reset), seed, sides, frame
// all, and a slider per #define.
PanelActions DrawPanel(const std::string& path, Shown& shown, bool busy, double frameMs, Job& job) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Sylva", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::TextWrapped("%s", fs::path(path).filename().string().c_str());
  PanelActions act;
  bool& changed = act.changed;
  int steps = job.steps < 0 ? shown.derivationLength : job.steps;
  if (ImGui::SliderInt("step", &steps, 0, std::max(shown.derivationLength, 1))) {
    job.steps = steps;
    shown.playing = false;
    changed = true;
  }
  if (ImGui::Button(shown.playing ? "pause" : "play")) {
    shown.playing = !shown.playing;
    if (shown.playing && steps >= shown.derivationLength) {  // play from the axiom
      job.steps = 0;
      changed = true;
    }
    shown.lastPlayed = Clock::now();
  }
  ImGui::SameLine();
  if (ImGui::Button("step") && steps < shown.derivationLength) {
    job.steps = steps + 1;
    shown.playing = false;
    changed = true;
  }
  ImGui::SameLine();
  if (ImGui::Button("reset")) {
    job.steps = 0;
    shown.playing = false;
    changed = true;
  }
  ImGui::SameLine();
  if (ImGui::Button("frame all")) act.frameAll = true;
  int seed = int(job.seed.value_or(1));
  if (ImGui::InputInt("seed", &seed)) {
    job.seed = uint64_t(std::max(seed, 0));
    changed = true;
  }
  if (ImGui::Checkbox("screen-space detail", &job.lod)) changed = true;
  if (!job.lod && ImGui::SliderInt("sides", &job.sides, 3, 32)) changed = true;
  if (!shown.constants.empty() &&
      ImGui::CollapsingHeader("constants", ImGuiTreeNodeFlags_DefaultOpen)) {
    for (const auto& [name, value] : shown.constants) {
      float v = float(job.overrides.count(name) ? job.overrides[name] : value);
      const auto range = shown.ranges.count(name) ? shown.ranges[name] : SliderRangeFor(value);
      if (ImGui::SliderFloat(name.c_str(), &v, range.first, range.second)) {
        job.overrides[name] = v;
        changed = true;
      }
    }
    if (!job.overrides.empty() && ImGui::Button("file values")) {
      job.overrides.clear();
      changed = true;
    }
  }
  if (busy) ImGui::ProgressBar(-1.0f * float(ImGui::GetTime()), ImVec2(-1, 0), "deriving...");
  ImGui::Separator();
  if (shown.plant) {
    ImGui::Text("modules %llu, triangles %zu",
                static_cast<unsigned long long>(shown.plant->modules), shown.plant->triangles);
    ImGui::Text("derive %.1f ms, turtle %.1f ms, mesh %.1f ms", shown.plant->deriveMs,
                shown.plant->turtleMs, shown.plant->tessellateMs);
  }
  ImGui::Text("frame %.1f ms", frameMs);
  if (!shown.diagnostics.empty() &&
      ImGui::CollapsingHeader("diagnostics", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (shown.lastFailed)
      ImGui::TextColored(ImVec4(0.8f, 0.1f, 0.1f, 1), "errors: showing the last good plant");
    ImGui::TextWrapped("%s", shown.diagnostics.c_str());
  }
  ImGui::End();
  return act;
}

// The drawn scene of a result, as `sylva render` draws it (PlantScene).
draw::DrawList SceneOf(Result& r) {
  draw::DrawList list =
      PlantScene(r.view, std::make_shared<const mesh::TriangleMesh>(std::move(r.mesh)), r.palette,
                 std::move(r.lines), r.box, r.camera);
  r.lines = {};
  return list;
}

}  // namespace

int RunView(const ViewCommand& cmd, std::ostream& out, std::ostream& err) {
  int width = 1280, height = 720;
  {
    int n = 0;
    if (std::sscanf(cmd.size.c_str(), "%dx%d%n", &width, &height, &n) != 2 ||
        size_t(n) != cmd.size.size() || width < 64 || height < 64 || width > 8192 ||
        height > 8192) {
      err << "sylva: error: --size '" << cmd.size << "': expected WxH from 64x64 to 8192x8192\n";
      return kExitBadInput;
    }
  }
  if (!cmd.screenshot.empty() && !render::IsImagePath(cmd.screenshot)) {
    err << "sylva: error: " << cmd.screenshot
        << ": unknown image format; use .png, .jpg or .jpeg\n";
    return kExitBadInput;
  }
  const std::string path = cmd.file.empty() ? DefaultGrammar() : cmd.file;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    err << path << ": error: cannot read file\n";
    return kExitBadInput;
  }
  if (IsSceneFile(path)) {
    if (cmd.steps || cmd.seed) {
      err << "sylva: error: -n and --seed are for grammars; a scene sets them on <plant> and "
             "<forest>\n";
      return kExitBadInput;
    }
    if (!cmd.view.empty()) {
      err << "sylva: error: --view is for grammars (a cpfg view file); a scene has its <camera>\n";
      return kExitBadInput;
    }
    ViewCommand scene = cmd;
    scene.file = path;  // the bundled scene when no file was given
    return RunViewScene(scene, width, height, out, err);
  }
  if (cmd.time) {
    err << "sylva: error: --time is for scenes (.xml); a grammar has its derivation step (-n)\n";
    return kExitBadInput;
  }
  Job job;
  if (!ParseDefines(cmd.defines, &job.overrides, err)) return kExitBadInput;
  if (cmd.steps) job.steps = *cmd.steps;
  job.seed = cmd.seed;
  job.threads = cmd.threads;
  Window window;
  if (int code = OpenWindow(width, height, "Sylva - " + path, cmd.frames == 0, window, err))
    return code;
  // Declared after the window: its GL objects are destroyed before the context.
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  (*renderer)->SetShadowMapSize(kViewerShadowMapSize);  // interactive: cheaper shadow samples
  // The default scene of the plant shown (a ground plane, the default lights).
  draw::DrawList drawn;
  // A new tessellation on its way to the GPU (Renderer::Stage), and its scene.
  std::optional<Result> pending, queued;  // queued: the next, while `pending` uploads
  draw::DrawList pendingScene;
  bool pendingUploaded = false;  // Stage() completed: shown from the next frame

  int exitCode = kExitOk;
  WorkerState state;  // the worker's alone; outlives it
  Worker<Job, Result> worker([&state](const Job& j) { return RunJobSafely(j, state); });
  job.path = path;
  job.viewPath = cmd.view;
  job.strict = cmd.strict;
  job.width = width;
  job.height = height;
  uint64_t nextId = 1;
  Shown shown;
  render::Camera camera;
  bool framed = false;
  // The view of the last job posted: the camera moving far from it posts
  // a re-tessellation; meanwhile the shown mesh stays on screen.
  render::Camera posted;
  int retessellations = 0;
  uint64_t reportedFailure = 0;  // the job id of the last failed build reported
  double slowestFrameMs = 0, slowestSwapMs = 0;
  // Of the swap: the slowest frame that uploads a slice of a new mesh, and
  // the slowest that first shows one (its extra Draw time included).
  double slowestSliceMs = 0, slowestShowMs = 0;
  // Draw time (with the swap's work) of frames plain, uploading a slice,
  // and showing a new mesh: their means compare robustly on a busy machine.
  double drawSum[3] = {0, 0, 0};
  int drawCount[3] = {0, 0, 0};
  std::optional<double> plainDrawMs;  // the last Draw of a frame without a new mesh
  std::optional<double> lastPlainMs;  // the last Draw of a frame without any swap work
  auto post = [&] {
    job.id = nextId++;
    job.camera = framed ? std::optional<render::Camera>(camera) : std::nullopt;
    posted = camera;
    worker.Post(job);
  };
  post();
  fs::file_time_type mtime = fs::last_write_time(path, ec);
  std::map<std::string, fs::file_time_type> watched;  // the view file and its colours
  auto lastPoll = Clock::now();
  double frameMs = 0;
  int frame = 0;
  int shots = 0;
  bool screenshotKeyDown = false;  // one picture per press of P, however long it is held
  bool lines = false;              // the plant shown is a 2D figure drawn as lines
  bool pixelWidths = false;        // the plant shown has pixel widths
  PlantLook look = PlantLook::kMesh;
  MouseCamera mouse;

  while (!glfwWindowShouldClose(window.handle)) {
    const auto frameStart = Clock::now();
    glfwPollEvents();
    // Reload on change (polled four times a second).
    if (Clock::now() - lastPoll > std::chrono::milliseconds(250)) {
      lastPoll = Clock::now();
      auto t = fs::last_write_time(path, ec);
      bool changed = !ec && t != mtime;
      if (changed) mtime = t;
      // The view file and its colour files too.
      for (auto& [f, when] : watched) {
        auto tf = fs::last_write_time(f, ec);
        if (!ec && tf != when) {
          when = tf;
          changed = true;
        }
      }
      if (changed) {
        ++job.reload;
        post();
      }
    }
    // The time a new mesh costs this thread in this frame: building its
    // scene, a slice of its upload (Renderer::Stage), and in the frame that
    // shows it what its Draw takes beyond a plain one.
    std::optional<double> swapMs;
    bool newScene = false;  // also the first mesh, which replaces none (not timed)
    std::optional<Result> taken = worker.Take();
    bool staged = false;  // taken's scene is pendingScene, already on the GPU
    if (auto& r = taken) {
      // Diagnostics when they arrive (a mesh may be shown frames later).
      shown.diagnostics = r->diagnostics;
      // Report each failed build once, also when a newer view of the last
      // good plant (stale) overtook the failure itself.
      if ((!r->ok || r->stale) && r->failedId != reportedFailure) {
        reportedFailure = r->failedId;
        err << "sylva view: the grammar has errors; keeping the last good plant\n"
            << shown.diagnostics;
      }
    }
    if (taken && taken->ok && shown.plant && taken->view.look != PlantLook::kLines && !lines) {
      // A new tessellation of the plant shown: uploaded in slices over the
      // next frames while the shown one is drawn, then swapped in. One
      // arriving meanwhile waits (the newest only), so uploads finish.
      queued = std::move(taken);
      taken.reset();
    }
    if (!pending && queued) {
      const auto t = Clock::now();
      pendingScene = SceneOf(*queued);
      pending = std::move(queued);
      queued.reset();
      pendingUploaded = false;
      swapMs = std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    }
    if (pending && pendingUploaded) {
      // Uploaded by the last frame: shown from this one.
      taken = std::move(pending);
      pending.reset();
      pendingUploaded = false;
      staged = true;
    } else if (pending) {
      const auto t = Clock::now();
      auto done = (*renderer)->Stage(pendingScene, kUploadBytesPerFrame);
      if (!done) {
        exitCode = Report(done.error(), err);
        break;
      }
      swapMs =
          swapMs.value_or(0) + std::chrono::duration<double, std::milli>(Clock::now() - t).count();
      pendingUploaded = *done;
    }
    if (auto& r = taken) {
      if (r->ok) {
        shown.constants = r->constants;
        UpdateSliderRanges(r->constants, r->overridden, shown.ranges);
        shown.derivationLength = r->derivationLength;
        shown.id = r->id;
        const PlantLook wasLook = look;
        const bool wasOrthographic = shown.plant && shown.plant->view.orthographic;
        look = r->view.look;
        lines = look == PlantLook::kLines;
        pixelWidths = r->pixelWidths;
        for (const std::string& f : r->watched)
          if (!watched.count(f)) watched[f] = fs::last_write_time(f, ec);
        // A first mesh, or a 2D figure: its scene, uploaded whole in the
        // next Draw (the first, replacing none, is not timed).
        const auto swapStart = Clock::now();
        drawn = staged ? std::move(pendingScene) : SceneOf(*r);
        if (shown.plant)
          swapMs = swapMs.value_or(0) +
                   std::chrono::duration<double, std::milli>(Clock::now() - swapStart).count();
        newScene = true;
        if (!framed) {
          // The view the mesh was tessellated for: `sylva render`'s framing.
          camera = r->camera;
          posted = camera;
          framed = true;
        } else if (look != wasLook || r->view.orthographic != wasOrthographic) {
          // A plant became a 2D figure or back, or its view file another
          // projection: framed again as render frames it (a mesh made for
          // the last view is re-tessellated for this one).
          camera = FramePlant(r->view, r->box, double(width) / height);
        }
        shown.lastFailed = r->stale;  // a view of the last good plant keeps the errors shown
        shown.plant = std::move(r);
      } else {
        // Keep the last good plant (what went wrong is reported above).
        shown.lastFailed = true;
        // A screenshot of a plant that cannot be built: nothing will come.
        if (cmd.frames > 0 && !shown.plant) {
          exitCode = kExitBadInput;
          break;
        }
      }
    }
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(window.handle, &fbw, &fbh);
    if (fbw > 0 && fbh > 0 && (fbw != (*renderer)->width() || fbh != (*renderer)->height())) {
      (void)(*renderer)->Resize(fbw, fbh);
    }
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    // After NewFrame: ImGui knows whether this frame's click is on the panel.
    mouse.Update(window.handle, camera);
    if (framed) camera.azimuth += cmd.orbit;
    // Re-tessellation applies to meshes only (a 2D figure drawn as lines is
    // not tessellated); pixel widths follow the view with or without lod.
    const bool retessellate = framed && (job.lod || pixelWidths) && !lines;
    if (fbw > 0 && fbh > 0 && (fbw != job.width || fbh != job.height)) {
      job.width = fbw;
      job.height = fbh;
      if (retessellate) post();
    }
    const PanelActions act = DrawPanel(path, shown, worker.Busy(), frameMs, job);
    // Playing: the next step once the last one is shown (at most 4 a second).
    if (shown.playing && !worker.Busy() && shown.id + 1 == nextId &&
        Clock::now() - shown.lastPlayed > std::chrono::milliseconds(250)) {
      const int at = job.steps < 0 ? shown.derivationLength : job.steps;
      if (at < shown.derivationLength) {
        job.steps = at + 1;
        shown.lastPlayed = Clock::now();
        post();
      } else {
        shown.playing = false;
      }
    }
    if (act.changed) post();
    const bool frameKey =
        glfwGetKey(window.handle, GLFW_KEY_F) == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard;
    if ((act.frameAll || frameKey) && shown.plant)
      camera = FrameAll(shown.plant->view, shown.plant->box, double(fbw) / std::max(fbh, 1),
                        camera.azimuth, camera.elevation);
    // Re-tessellate in the background once the camera has moved far
    // enough, one job at a time; the shown mesh is drawn meanwhile.
    if (retessellate && !worker.Busy() && !pending && !queued && MovedFarEnough(camera, posted)) {
      post();
      ++retessellations;
    }
    ImGui::Render();

    const auto drawStart = Clock::now();
    if (Status s = (*renderer)->Draw(drawn, camera); !s.ok()) {
      exitCode = Report(s.error(), err);
      break;
    }
    // Measuring (--frames): wait for the GPU, so drawMs holds the drawing
    // itself (a new mesh's shadow pass included), not only its commands.
    if (cmd.frames > 0) (*renderer)->Finish();
    const double drawMs =
        std::chrono::duration<double, std::milli>(Clock::now() - drawStart).count();
    // The upload is what the frame with a new mesh draws longer than the
    // last frame without one (the first mesh has none to compare with).
    if (!newScene && !swapMs) lastPlainMs = drawMs;
    if (!newScene) {
      plainDrawMs = drawMs;
      // A slice of an upload (and of the next shadow map): its work and
      // what its Draw took beyond the last plain one.
      if (swapMs && lastPlainMs)
        slowestSliceMs = std::max(slowestSliceMs, *swapMs + std::max(0.0, drawMs - *lastPlainMs));
    } else if (swapMs && plainDrawMs) {
      slowestShowMs = std::max(slowestShowMs, *swapMs + std::max(0.0, drawMs - *plainDrawMs));
    }
    slowestSwapMs = std::max(slowestSliceMs, slowestShowMs);
    if (frame > 1) {  // past the first mesh's frames
      const int kind = newScene ? 2 : swapMs ? 1 : 0;
      drawSum[kind] += drawMs + swapMs.value_or(0);
      ++drawCount[kind];
    }
    (*renderer)->PresentToWindow(fbw, fbh);
    glViewport(0, 0, fbw, fbh);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    ++frame;
    const bool keyDown =
        glfwGetKey(window.handle, GLFW_KEY_P) == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard;
    const bool key = keyDown && !screenshotKeyDown;
    screenshotKeyDown = keyDown;
    const bool done = cmd.frames > 0 && frame >= cmd.frames && shown.plant.has_value();
    if (key || done) {
      std::string file =
          done ? cmd.screenshot : "sylva-screenshot-" + std::to_string(++shots) + ".png";
      if (!file.empty()) {
        if (Status s = render::WriteImage(render::ReadWindowPixels(fbw, fbh), file); !s.ok()) {
          exitCode = Report(s.error(), err);
        } else {
          out << "screenshot: " << file << "\n";
        }
      }
    }
    glfwSwapBuffers(window.handle);
    frameMs = std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
    if (frame > 1) slowestFrameMs = std::max(slowestFrameMs, frameMs);  // past the first upload
    if (done) break;
    // Wait for the first plant no longer than a minute when taking a screenshot.
    if (cmd.frames > 0 && frame > cmd.frames + 6000) {
      err << "sylva view: no plant to show after " << frame << " frames\n";
      exitCode = kExitRuntime;
      break;
    }
  }
  if (cmd.frames > 0) {
    auto mean = [&](int k) { return drawCount[k] ? drawSum[k] / drawCount[k] : 0.0; };
    char line[400];
    std::snprintf(line, sizeof line,
                  "frames: %d, re-tessellations: %d, slowest frame: %.1f ms, slowest mesh swap: "
                  "%.1f ms (upload slice %.1f ms, first frame shown %.1f ms); mean draw: plain "
                  "%.1f ms (%d), uploading %.1f ms (%d), showing a new mesh %.1f ms (%d)\n",
                  frame, retessellations, slowestFrameMs, slowestSwapMs, slowestSliceMs,
                  slowestShowMs, mean(0), drawCount[0], mean(1), drawCount[1], mean(2),
                  drawCount[2]);
    out << line;
  }
  return exitCode;
}

}  // namespace sylva::app
