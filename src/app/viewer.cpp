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
#include <sstream>
#include <thread>

#include "app/cli.h"
#include "app/commands.h"
#include "app/viewer_window.h"
#include "plant/plant.h"
#include "plant/surface_library.h"
#include "render/camera.h"
#include "render/renderer.h"

namespace sylva::app {

// cli_render.cpp: the screen-space view of a camera.
mesh::ScreenView ViewOf(const render::Camera& camera, int width, int height, double eps);

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Job {
  uint64_t id = 0;
  std::string path;
  uint64_t reload = 0;  // bumped when the file changes: the plant is rebuilt
  std::map<std::string, double> overrides;
  std::optional<uint64_t> seed;
  int steps = -1;
  int sides = 8;        // uniform detail, when lod is off
  bool lod = true;      // screen-space detail for the camera (docs/lod.md)
  bool strict = false;  // warnings are errors
  // The view to tessellate for (with lod); empty: the framing of `sylva render`.
  std::optional<render::Camera> camera;
  int width = 1280, height = 720;
};

// Jobs that differ only in the view (or the detail) reuse the plant.
bool SamePlant(const Job& a, const Job& b) {
  return a.path == b.path && a.reload == b.reload && a.overrides == b.overrides &&
         a.seed == b.seed && a.steps == b.steps && a.strict == b.strict;
}

struct Result {
  uint64_t id = 0;
  bool ok = false;
  bool rebuilt = false;     // a new plant, not only a new tessellation
  bool stale = false;       // the last good plant: the request's own failed to build
  uint64_t failedId = 0;    // with !ok or stale: the job whose build failed
  std::string diagnostics;  // errors and warnings, formatted
  mesh::TriangleMesh mesh;
  mesh::Palette palette;
  mesh::Box bounds;       // the whole plant's (ground and shadows are fitted to it)
  render::Camera camera;  // the view it was tessellated for
  Vec3 lo{0, 0, 0}, hi{1, 1, 1};
  uint64_t modules = 0;
  int derivationLength = 0;
  std::vector<std::pair<std::string, double>> constants;  // file order not kept: sorted
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
    spec.until = plant::Stage::kGeometry;
    plant::PlantResult built = plant::BuildPlant(spec);
    std::string diagnostics = built.diagnostics.FormatAll();
    std::optional<mesh::Box> bounds;
    if (built.plant && job.strict && !built.diagnostics.items.empty()) {
      diagnostics += "sylva: error: --strict: warnings are treated as errors\n";
    } else if (built.plant) {
      auto b = plant::MeshBounds(*built.plant, spec);
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
  plant::PlantSpec spec = st.spec;
  spec.detail.sides = job.sides;
  const bool empty = !(st.bounds.lo.array() <= st.bounds.hi.array()).all();
  const Vec3 lo = empty ? Vec3::Zero() : st.bounds.lo, hi = empty ? Vec3::Ones() : st.bounds.hi;
  r.camera = job.camera
                 ? *job.camera
                 : render::Camera::Frame(lo, hi, double(job.width) / job.height, 30, 12, false);
  if (job.lod) {
    spec.view = ViewOf(r.camera, job.width, job.height, 0.5);
    spec.view->shadowFrom = render::KeyLightDirection();
    spec.view->shadowPlaneY = lo.y();
    spec.view->shadowTexelsPerUnit = render::ShadowTexelsPerUnit(st.bounds);
    spec.view->coverage = true;
    spec.history = &st.history;
  } else {
    st.history = {};  // levels of another detail mean nothing to the next view
  }
  DiagnosticList warnings;
  if (Status s = plant::Tessellate(p, spec, warnings); !s.ok()) {
    r.diagnostics += s.error().message + "\n";
    return r;
  }
  r.derivationLength = p.grammar.derivationLength;
  for (const auto& [k, v] : p.grammar.constants) r.constants.emplace_back(k, v);
  std::sort(r.constants.begin(), r.constants.end());
  r.mesh = std::move(p.mesh);
  p.mesh = mesh::TriangleMesh();
  r.palette = p.palette;
  r.modules = p.DrawnWord().size();
  r.bounds = st.bounds;
  r.lo = lo;
  r.hi = hi;
  r.deriveMs = p.time.parse + p.time.derive + p.time.interpret;
  r.turtleMs = p.time.turtle;
  r.tessellateMs = p.time.tessellate;
  r.ok = true;
  return r;
}

// The camera has moved far enough from the one the shown mesh was
// tessellated for to re-tessellate: 5 % nearer or farther, 2 degrees
// around, or the target 2 % of the distance away.
bool MovedFarEnough(const render::Camera& a, const render::Camera& b) {
  return std::abs(std::log(a.distance / b.distance)) > 0.05 ||
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
  std::string diagnostics;
  bool lastFailed = false;
  std::vector<std::pair<std::string, double>> constants;
  int derivationLength = 0;
};

// The control panel: step, seed, sides and a slider per #define; true when
// the job changed.
bool DrawPanel(const std::string& path, const Shown& shown, bool busy, double frameMs, Job& job) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Sylva", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::TextWrapped("%s", fs::path(path).filename().string().c_str());
  bool changed = false;
  int steps = job.steps < 0 ? shown.derivationLength : job.steps;
  if (ImGui::SliderInt("step", &steps, 0, std::max(shown.derivationLength, 1))) {
    job.steps = steps;
    changed = true;
  }
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
      const float lo = value > 0 ? 0.0f : float(value) - 10.0f;
      const float hi = value > 0 ? float(value) * 2.0f : float(value) + 10.0f;
      if (ImGui::SliderFloat(name.c_str(), &v, lo, hi)) {
        job.overrides[name] = v;
        changed = true;
      }
    }
  }
  if (busy) ImGui::ProgressBar(-1.0f * float(ImGui::GetTime()), ImVec2(-1, 0), "deriving...");
  ImGui::Separator();
  if (shown.plant) {
    ImGui::Text("modules %llu, triangles %zu",
                static_cast<unsigned long long>(shown.plant->modules),
                shown.plant->mesh.triangleCount());
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
  return changed;
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
    ViewCommand scene = cmd;
    scene.file = path;  // the bundled scene when no file was given
    return RunViewScene(scene, width, height, out, err);
  }
  if (cmd.time || !cmd.defines.empty() || cmd.threads) {
    err << "sylva: error: --time, -D and --threads are for scenes (.xml); a grammar's #defines "
           "have sliders in the viewer\n";
    return kExitBadInput;
  }
  Window window;
  if (int code = OpenWindow(width, height, "Sylva - " + path, cmd.frames == 0, window, err))
    return code;
  // Declared after the window: its GL objects are destroyed before the context.
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  (*renderer)->SetGround(true);

  int exitCode = kExitOk;
  WorkerState state;  // the worker's alone; outlives it
  Worker<Job, Result> worker([&state](const Job& j) { return RunJobSafely(j, state); });
  Job job;
  job.path = path;
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
  auto post = [&] {
    job.id = nextId++;
    job.camera = framed ? std::optional<render::Camera>(camera) : std::nullopt;
    posted = camera;
    worker.Post(job);
  };
  post();
  fs::file_time_type mtime = fs::last_write_time(path, ec);
  auto lastPoll = Clock::now();
  double frameMs = 0;
  int frame = 0;
  int shots = 0;
  MouseCamera mouse;

  while (!glfwWindowShouldClose(window.handle)) {
    const auto frameStart = Clock::now();
    glfwPollEvents();
    // Reload on change (polled four times a second).
    if (Clock::now() - lastPoll > std::chrono::milliseconds(250)) {
      lastPoll = Clock::now();
      auto t = fs::last_write_time(path, ec);
      if (!ec && t != mtime) {
        mtime = t;
        ++job.reload;
        post();
      }
    }
    if (auto r = worker.Take()) {
      shown.diagnostics = r->diagnostics;
      // Report each failed build once, also when a newer view of the last
      // good plant (stale) overtook the failure itself.
      if ((!r->ok || r->stale) && r->failedId != reportedFailure) {
        reportedFailure = r->failedId;
        err << "sylva view: the grammar has errors; keeping the last good plant\n"
            << shown.diagnostics;
      }
      if (r->ok) {
        shown.constants = r->constants;
        shown.derivationLength = r->derivationLength;
        // The only work a new tessellation costs this thread: the upload.
        const auto swapStart = Clock::now();
        (*renderer)->SetMesh(r->mesh, r->palette, &r->bounds);
        slowestSwapMs =
            std::max(slowestSwapMs,
                     std::chrono::duration<double, std::milli>(Clock::now() - swapStart).count());
        if (!framed) {
          camera = r->camera;
          posted = camera;
          framed = true;
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
    mouse.Update(window.handle, camera);
    if (framed) camera.azimuth += cmd.orbit;
    if (fbw > 0 && fbh > 0 && (fbw != job.width || fbh != job.height)) {
      job.width = fbw;
      job.height = fbh;
      if (framed && job.lod) post();
    }
    // Re-tessellate in the background once the camera has moved far
    // enough, one job at a time; the shown mesh is drawn meanwhile.
    if (framed && job.lod && !worker.Busy() && MovedFarEnough(camera, posted)) {
      post();
      ++retessellations;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (DrawPanel(path, shown, worker.Busy(), frameMs, job)) post();
    ImGui::Render();

    (*renderer)->Draw(camera);
    (*renderer)->PresentToWindow(fbw, fbh);
    glViewport(0, 0, fbw, fbh);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    ++frame;
    const bool key =
        glfwGetKey(window.handle, GLFW_KEY_P) == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard;
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
    char line[256];
    std::snprintf(line, sizeof line,
                  "frames: %d, re-tessellations: %d, slowest frame: %.1f ms, slowest mesh swap: "
                  "%.1f ms\n",
                  frame, retessellations, slowestFrameMs, slowestSwapMs);
    out << line;
  }
  return exitCode;
}

}  // namespace sylva::app
