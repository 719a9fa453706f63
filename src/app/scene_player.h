// Playing a scene in the viewer, GL-free (tests drive it without a window):
// the scene read, built and simulated, and a clock the viewer's panel
// controls (play, pause, step, reset, seek).
//
//   SceneLoad load = LoadSceneForView(path, {}, false, 0);   // worker thread
//   auto player = ScenePlayer::Create(std::move(load.scene), 0);
//   (*player)->Play();
//   every drawn frame:
//     (void)(*player)->Update(wallSecondsSinceLastFrame, 0.03);
//     renderer.Draw((*player)->Frame(), camera);
//
// Update never advances the simulation by more than one frame (1 / fps) while
// playing: a frame whose step takes longer than a frame of real time slows
// playback down (slower() says so) instead of blocking the window. A seek
// (the time slider, --time) simulates forward within a wall-clock budget per
// drawn frame; seeking backward rebuilds the Simulation at t = 0 first.
// Rebuilding (reset, seeking back) runs on its own thread: creating a
// Simulation can take a while (snowy_forest.xml's colliders, ~0.4 s here),
// so the window goes on drawing the old state until the new one is ready.
#pragma once

#include <future>
#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "draw/draw_list.h"
#include "scene/build.h"
#include "scene/scene.h"
#include "scene/simulation.h"

namespace sylva::app {

// A scene read and built: what the Simulation is created from (it keeps
// references, so this lives on the heap and never moves).
struct LoadedScene {
  scene::Scene scene;
  scene::BuiltScene built;
  draw::DrawList staticList;  // lights, sky, terrain, plants, forests
  int threads = 0;            // simulation threads (0: all cores)
};

struct SceneLoad {
  std::unique_ptr<LoadedScene> scene;  // null on an error
  std::string diagnostics;             // errors and warnings, formatted
  int exit = 0;                        // the exit status the diagnostics call for
  // The files to poll for changes: the scene and its includes, the grammars
  // and .obj meshes it names. Only the root when the scene cannot be read.
  std::vector<std::string> watched;
};

// Reads (strictly; `defines` as -D gives them; `strict`: warnings are
// errors), checks the grammars and builds the scene. Never throws: running
// out of memory is a failed load.
SceneLoad LoadSceneForView(const std::string& path, const std::vector<std::string>& defines,
                           bool strict, int threads);

class ScenePlayer {
 public:
  // Creates the simulation at t = 0, paused. An error (a bad combination
  // found by the simulation) is returned.
  static Expected<std::unique_ptr<ScenePlayer>> Create(std::unique_ptr<LoadedScene> loaded);

  const LoadedScene& loaded() const { return *loaded_; }
  double time() const;
  double frameLength() const { return 1.0 / loaded_->scene.simulation.fps; }
  double duration() const { return loaded_->scene.simulation.duration; }
  bool playing() const { return playing_; }
  bool seeking() const { return seekTarget_ >= 0; }
  // A new Simulation at t = 0 is being created (reset, seeking back).
  bool rebuilding() const { return pending_.valid(); }
  double seekTarget() const { return seekTarget_; }
  // Playback fell behind real time within the last second of playing.
  bool slower() const { return playing_ && sinceDrop_ < 1.0; }
  // Wall-clock seconds the last simulation frame took.
  double lastStepSeconds() const { return lastStep_; }
  // The error that stopped the simulation (an explosion), or empty.
  const std::string& error() const { return error_; }

  // Play from here (from t = 0 when at or past the end).
  void Play();
  void Pause() { playing_ = false; }
  // Pauses and advances one frame.
  Status Step();
  // Back to t = 0: a new Simulation (cancels a seek), created in the
  // background and swapped in by a later Update. Keeps playing if it was.
  void Reset();
  // Moves toward time t (at least 0; the slider stops at the duration,
  // --time may go past it) in the next Updates.
  void Seek(double t);
  // One drawn frame: `wallSeconds` of real time passed since the last one.
  // Seeking: simulate toward the target for at most `budgetSeconds` (0: all
  // the way, waiting for a rebuild too). Playing: at most one simulation
  // frame. Stops at the end of
  // the scene's duration. A failed step pauses and sets error().
  Status Update(double wallSeconds, double budgetSeconds);

  // The frame to draw: the static list plus particles, cloth and boids.
  draw::DrawList Frame() const;
  size_t particles() const;

 private:
  explicit ScenePlayer(std::unique_ptr<LoadedScene> loaded) : loaded_(std::move(loaded)) {}
  using Created = Expected<std::unique_ptr<scene::Simulation>>;
  Created MakeSimulation() const;
  void StartRebuild();              // MakeSimulation on another thread
  Status FinishRebuild(bool wait);  // swaps the new Simulation in when ready
  Status Advance(double t);         // one AdvanceTo with its timing and error
  std::unique_ptr<LoadedScene> loaded_;
  std::unique_ptr<scene::Simulation> sim_;
  bool playing_ = false;
  double clock_ = 0;        // playback's real-time clock (scene seconds)
  double seekTarget_ = -1;  // < 0: not seeking
  double sinceDrop_ = 1e9;  // seconds played since playback last fell behind
  double lastStep_ = 0;
  std::string error_;
  // Declared last: destroyed (waited for) before what it reads.
  std::future<Created> pending_;
};

// Triangles drawn by a list (every mesh times its instances).
size_t TrianglesOf(const draw::DrawList& list);

}  // namespace sylva::app
