// The viewer playing a scene (.xml). Threads: the UI thread owns the window,
// ImGui, every GL call and the ScenePlayer (the simulation advances there,
// at most one frame per drawn frame while playing, within a time budget
// while seeking); one worker reads and builds the scene when it or a file it
// names changes, and hands back a LoadedScene. A failed reload keeps the
// last good scene on screen with the diagnostics in the panel.
#include <GL/glew.h>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "app/scene_camera.h"
#include "app/scene_player.h"
#include "app/viewer.h"
#include "app/viewer_window.h"
#include "render/renderer.h"

namespace sylva::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// A wall-clock budget for simulating while seeking, per drawn frame.
constexpr double kSeekBudgetSeconds = 0.03;

struct SceneJob {
  uint64_t id = 0;
  std::string path;
  std::vector<std::string> defines;
  bool strict = false;
  int threads = 0;
};

struct SceneResult {
  uint64_t id = 0;
  SceneLoad load;                       // load.scene moved into the player
  std::unique_ptr<ScenePlayer> player;  // at t = 0; null on an error
};

// Loads, builds and creates the simulation (which may take a while: the
// colliders of a forest) off the UI thread.
SceneResult RunSceneJob(const SceneJob& job) {
  SceneResult r;
  r.id = job.id;
  r.load = LoadSceneForView(job.path, job.defines, job.strict, job.threads);
  if (!r.load.scene) return r;
  try {
    auto created = ScenePlayer::Create(std::move(r.load.scene));
    if (created) {
      r.player = std::move(*created);
    } else {
      r.load.diagnostics += created.error().Format();
      r.load.exit = created.error().kind == ErrorKind::kInput ? kExitBadInput : kExitRuntime;
    }
  } catch (const std::bad_alloc&) {
    r.load.diagnostics += job.path + ": error: out of memory creating the simulation\n";
    r.load.exit = kExitRuntime;
  }
  return r;
}

// The files of the scene and their modification times.
class FileWatch {
 public:
  // Watches `paths` (and, with keepOthers, the files watched already); a
  // path already watched keeps the time recorded before its reload began,
  // so an edit made while loading is still seen.
  void Set(const std::vector<std::string>& paths, bool keepOthers = false) {
    std::vector<Entry> next;
    if (keepOthers) next = entries_;
    for (const std::string& p : paths) {
      auto known = [&](const Entry& e) { return e.path == p; };
      if (std::find_if(next.begin(), next.end(), known) != next.end()) continue;
      auto it = std::find_if(entries_.begin(), entries_.end(), known);
      next.push_back(it != entries_.end() ? *it : Entry{p, TimeOf(p)});
    }
    entries_ = std::move(next);
  }
  // True when a file's time changed (or it appeared or went) since the
  // last call; records the new times.
  bool Changed() {
    bool changed = false;
    for (Entry& e : entries_) {
      const auto t = TimeOf(e.path);
      if (t != e.time) {
        e.time = t;
        changed = true;
      }
    }
    return changed;
  }

 private:
  struct Entry {
    std::string path;
    fs::file_time_type time;
  };
  static fs::file_time_type TimeOf(const std::string& path) {
    std::error_code ec;
    const auto t = fs::last_write_time(path, ec);
    return ec ? fs::file_time_type::min() : t;
  }
  std::vector<Entry> entries_;
};

// What the panel shows besides the player.
struct SceneShown {
  std::string diagnostics;
  bool lastFailed = false;
  size_t triangles = 0;
};

// The control panel. Acts on the player directly.
void DrawScenePanel(const std::string& path, ScenePlayer* player, const SceneShown& shown,
                    bool busy, double frameMs) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Sylva", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::TextWrapped("%s", fs::path(path).filename().string().c_str());
  if (player) {
    if (player->playing() ? ImGui::Button("pause") : ImGui::Button("play")) {
      if (player->playing()) {
        player->Pause();
      } else {
        player->Play();
      }
    }
    ImGui::SameLine();
    if (ImGui::Button("step")) (void)player->Step();  // an error shows in the panel
    ImGui::SameLine();
    if (ImGui::Button("reset")) player->Reset();
    float t = float(player->seeking() ? player->seekTarget() : player->time());
    const float end = float(std::max(player->duration(), player->time()));
    if (ImGui::SliderFloat("time", &t, 0.0f, end, "%.2f s")) player->Seek(t);
    ImGui::Text("t = %.3f s of %.3f s (%.0f fps)", player->time(), player->duration(),
                1.0 / player->frameLength());
    if (player->rebuilding()) {
      ImGui::TextColored(ImVec4(0.1f, 0.3f, 0.8f, 1), "starting again from t = 0...");
    } else if (player->seeking()) {
      ImGui::TextColored(ImVec4(0.1f, 0.3f, 0.8f, 1), "simulating to %.2f s...",
                         player->seekTarget());
    }
    if (player->slower()) {
      ImGui::TextColored(ImVec4(0.8f, 0.4f, 0.0f, 1), "running slower than real time");
    }
    ImGui::Text("particles %zu, triangles %zu", player->particles(), shown.triangles);
    ImGui::Text("simulation frame %.2f ms", player->lastStepSeconds() * 1e3);
    if (!player->error().empty()) {
      ImGui::TextColored(ImVec4(0.8f, 0.1f, 0.1f, 1), "the simulation stopped:");
      ImGui::TextWrapped("%s", player->error().c_str());
    }
  }
  if (busy) ImGui::ProgressBar(-1.0f * float(ImGui::GetTime()), ImVec2(-1, 0), "loading...");
  ImGui::Separator();
  ImGui::Text("frame %.1f ms", frameMs);
  if (!shown.diagnostics.empty() &&
      ImGui::CollapsingHeader("diagnostics", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (shown.lastFailed)
      ImGui::TextColored(ImVec4(0.8f, 0.1f, 0.1f, 1), "errors: showing the last good scene");
    ImGui::TextWrapped("%s", shown.diagnostics.c_str());
  }
  ImGui::End();
}

}  // namespace

int RunViewScene(const ViewCommand& cmd, int width, int height, std::ostream& out,
                 std::ostream& err) {
  const std::string& path = cmd.file;
  const bool screenshotMode = cmd.frames > 0;
  Window window;
  if (int code = OpenWindow(width, height, "Sylva - " + path, !screenshotMode, window, err))
    return code;
  // Declared after the window: its GL objects are destroyed before the context.
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  (*renderer)->SetShadowMapSize(2048);  // interactive: cheaper shadow samples

  int exitCode = kExitOk;
  Worker<SceneJob, SceneResult> worker(RunSceneJob);
  SceneJob job{0, path, cmd.defines, cmd.strict, cmd.threads};
  uint64_t nextId = 1;
  auto post = [&] {
    job.id = nextId++;
    worker.Post(job);
  };
  FileWatch watch;
  watch.Set({path});
  post();
  std::unique_ptr<ScenePlayer> player;
  SceneShown shown;
  render::Camera camera;
  auto lastPoll = Clock::now();
  auto lastFrame = Clock::now();
  double frameMs = 0;
  int readyFrames = 0;  // frames drawn at the asked time (screenshot mode)
  int frame = 0;
  int shots = 0;
  MouseCamera mouse;
  bool spaceWas = false, rightWas = false, pWas = false;

  while (!glfwWindowShouldClose(window.handle)) {
    const auto frameStart = Clock::now();
    const double wall =
        std::min(std::chrono::duration<double>(frameStart - lastFrame).count(), 0.25);
    lastFrame = frameStart;
    glfwPollEvents();
    // Reload on change (polled four times a second).
    if (Clock::now() - lastPoll > std::chrono::milliseconds(250)) {
      lastPoll = Clock::now();
      if (watch.Changed()) post();
    }
    if (auto r = worker.Take()) {
      SceneLoad& load = r->load;
      // A failed load may not know every file (an include or a grammar with
      // an error): go on watching the last good scene's files too, so that
      // fixing one reloads.
      watch.Set(load.watched, /*keepOthers=*/!r->player);
      shown.diagnostics = load.diagnostics;
      std::unique_ptr<ScenePlayer> next = std::move(r->player);
      if (next) {
        if (!player) {
          camera = SceneCamera(next->loaded().scene, next->loaded().built, double(width) / height);
          if (cmd.time) {
            next->Seek(*cmd.time);
          } else if (!screenshotMode) {
            next->Play();
          }
        } else {
          // The same moment of the edited scene, playing if it was.
          if (player->playing()) next->Play();
          next->Seek(player->seeking() ? player->seekTarget() : player->time());
        }
        player = std::move(next);
        shown.lastFailed = false;
        if (!shown.diagnostics.empty()) err << shown.diagnostics;
      } else {
        err << "sylva view: the scene has errors; keeping the last good scene\n"
            << shown.diagnostics;
        shown.lastFailed = true;
        // A screenshot of a scene that cannot be built: nothing will come.
        if (screenshotMode && !player) {
          exitCode = load.exit == kExitOk ? kExitBadInput : load.exit;
          break;
        }
      }
    }
    // Keys (when ImGui does not want them): space plays or pauses, the
    // right arrow steps one frame.
    if (player && !ImGui::GetIO().WantCaptureKeyboard) {
      const bool space = glfwGetKey(window.handle, GLFW_KEY_SPACE) == GLFW_PRESS;
      const bool right = glfwGetKey(window.handle, GLFW_KEY_RIGHT) == GLFW_PRESS;
      if (space && !spaceWas) {
        if (player->playing()) {
          player->Pause();
        } else {
          player->Play();
        }
      }
      if (right && !rightWas) (void)player->Step();
      spaceWas = space;
      rightWas = right;
    }
    if (player) {
      const std::string before = player->error();
      (void)player->Update(wall, screenshotMode ? 0.0 : kSeekBudgetSeconds);
      if (!player->error().empty() && before.empty()) {
        err << player->error();
        if (screenshotMode) {
          exitCode = kExitRuntime;
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
    mouse.Update(window.handle, camera);  // after NewFrame: is the click on the panel?
    DrawScenePanel(path, player.get(), shown, worker.Busy(), frameMs);
    ImGui::Render();

    const draw::DrawList list = player ? player->Frame() : draw::DrawList{};
    shown.triangles = TrianglesOf(list);
    if (Status s = (*renderer)->Draw(list, camera); !s.ok()) {
      err << s.error().Format();
      if (screenshotMode) {
        exitCode = kExitRuntime;
        break;
      }
    }
    (*renderer)->PresentToWindow(fbw, fbh);
    glViewport(0, 0, fbw, fbh);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    ++frame;
    if (player && !player->seeking() && !player->rebuilding()) ++readyFrames;
    // P saves a screenshot once per press.
    const bool pDown =
        glfwGetKey(window.handle, GLFW_KEY_P) == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard;
    const bool key = pDown && !pWas;
    pWas = pDown;
    const bool done = screenshotMode && readyFrames >= cmd.frames;
    if (key || done) {
      std::string file =
          done ? cmd.screenshot : "sylva-screenshot-" + std::to_string(++shots) + ".png";
      if (!file.empty()) {
        if (Status s = render::WriteImage(render::ReadWindowPixels(fbw, fbh), file); !s.ok()) {
          exitCode = Report(s.error(), err);
        } else {
          out << "screenshot: " << file << " at t = " << (player ? player->time() : 0.0) << " s\n";
        }
      }
    }
    glfwSwapBuffers(window.handle);
    frameMs = std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
    if (done) break;
    // Wait for the scene no longer than about a minute when taking a screenshot.
    if (screenshotMode && !player && frame > cmd.frames + 6000) {
      err << "sylva view: no scene to show after " << frame << " frames\n";
      exitCode = kExitRuntime;
      break;
    }
  }
  return exitCode;
}

}  // namespace sylva::app
