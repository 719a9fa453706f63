// The viewer's scene clock: see scene_player.h.
#include "app/scene_player.h"
#include "core/parallel.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <sstream>

#include "app/cli.h"
#include "app/commands.h"

namespace sylva::app {

using Clock = std::chrono::steady_clock;

static SceneLoad LoadUnsafe(const std::string& path, const std::vector<std::string>& defines,
                            bool strict, int threads) {
  SceneLoad load;
  load.watched.push_back(path);
  std::ostringstream err;
  std::optional<scene::Scene> s = LoadScene(path, defines, 0, err, &load.exit, strict);
  load.diagnostics = err.str();
  if (!s) return load;
  // Everything the scene reads, so an edit to any of it reloads.
  load.watched = s->files;
  auto watch = [&](const std::string& file) {
    if (!file.empty() &&
        std::find(load.watched.begin(), load.watched.end(), file) == load.watched.end())
      load.watched.push_back(file);
  };
  for (const scene::PlantDef& p : s->plants) watch(p.grammar);
  for (const scene::ForestDef& f : s->forests) watch(f.grammar);
  for (const scene::ParticlesDef& p : s->particles)
    if (!p.draw.mesh.empty() && p.draw.mesh[0] != '~') watch(p.draw.mesh);

  // The viewer's process pool: the loading worker and the window's clock
  // share it (a ParallelFor that finds it busy runs on its caller).
  scene::BuildOptions options;
  options.pool = &SharedPool(threads);
  scene::BuildResult built = scene::Build(*s, options);
  const int code = Report(built.diagnostics, err, 0, strict);
  load.diagnostics = err.str();
  if (!built.scene) {
    load.exit = code == kExitOk ? kExitRuntime : code;
    return load;
  }
  if (code != kExitOk) {
    load.exit = code;
    return load;
  }
  auto loaded = std::make_unique<LoadedScene>();
  loaded->scene = std::move(*s);
  loaded->built = std::move(*built.scene);
  loaded->staticList = scene::MakeDrawList(loaded->scene, loaded->built);
  loaded->threads = threads;
  load.scene = std::move(loaded);
  load.exit = kExitOk;
  return load;
}

SceneLoad LoadSceneForView(const std::string& path, const std::vector<std::string>& defines,
                           bool strict, int threads) {
  try {
    return LoadUnsafe(path, defines, strict, threads);
  } catch (const std::bad_alloc&) {
    SceneLoad load;
    load.watched.push_back(path);
    load.diagnostics = path + ": error: out of memory building the scene\n";
    load.exit = kExitRuntime;
    return load;
  }
}

Expected<std::unique_ptr<ScenePlayer>> ScenePlayer::Create(std::unique_ptr<LoadedScene> loaded) {
  std::unique_ptr<ScenePlayer> p(new ScenePlayer(std::move(loaded)));
  Created sim = p->MakeSimulation();
  if (!sim) return sim.error();
  p->sim_ = std::move(*sim);
  return p;
}

double ScenePlayer::time() const {
  return sim_ ? sim_->time() : 0.0;
}

ScenePlayer::Created ScenePlayer::MakeSimulation() const {
  DiagnosticList warnings;  // reported when the scene was loaded
  scene::SimulationOptions options;
  options.pool = &SharedPool(loaded_->threads);
  return scene::Simulation::Create(loaded_->scene, loaded_->built, options, warnings);
}

void ScenePlayer::StartRebuild() {
  if (pending_.valid()) return;  // one is on its way
  pending_ = std::async(std::launch::async, [this] {
    try {
      return MakeSimulation();
    } catch (const std::bad_alloc&) {
      return Created(MakeError({}, "out of memory creating the simulation"));
    }
  });
}

Status ScenePlayer::FinishRebuild(bool wait) {
  if (!pending_.valid()) return {};
  if (!wait && pending_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return {};
  Created sim = pending_.get();
  if (!sim) {
    error_ = sim.error().Format();
    playing_ = false;
    seekTarget_ = -1;
    return sim.error();
  }
  sim_ = std::move(*sim);
  clock_ = 0;
  error_.clear();
  return {};
}

void ScenePlayer::Reset() {
  seekTarget_ = -1;
  error_.clear();
  StartRebuild();
}

Status ScenePlayer::Advance(double t) {
  if (!sim_) return MakeError({}, "the scene has no simulation (it failed to start)");
  const auto start = Clock::now();
  Status s = sim_->AdvanceTo(t);
  lastStep_ = std::chrono::duration<double>(Clock::now() - start).count();
  if (!s.ok()) {
    error_ = s.error().Format();
    playing_ = false;
    seekTarget_ = -1;
  }
  return s;
}

void ScenePlayer::Play() {
  if (time() >= duration() - frameLength() / 2) Seek(0);
  playing_ = true;
  clock_ = time();
  sinceDrop_ = 1e9;
}

Status ScenePlayer::Step() {
  playing_ = false;
  seekTarget_ = -1;
  if (rebuilding()) return {};  // the next frame starts from t = 0
  return Advance(time() + frameLength());
}

void ScenePlayer::Seek(double t) {
  seekTarget_ = std::max(t, 0.0);
}

Status ScenePlayer::Update(double wallSeconds, double budgetSeconds) {
  if (Status s = FinishRebuild(budgetSeconds <= 0); !s.ok()) return s;
  if (rebuilding() || !error_.empty()) return {};
  const double half = frameLength() / 2;
  if (seekTarget_ >= 0) {
    // Backward: start again from t = 0, then simulate forward frame by frame.
    if (seekTarget_ < time() - half) {
      StartRebuild();
      if (Status s = FinishRebuild(budgetSeconds <= 0); !s.ok()) return s;
      if (rebuilding()) return {};
    }
    const auto start = Clock::now();
    while (time() < seekTarget_ - half) {
      if (Status s = Advance(std::min(seekTarget_, time() + frameLength())); !s.ok()) return s;
      if (budgetSeconds > 0 &&
          std::chrono::duration<double>(Clock::now() - start).count() >= budgetSeconds)
        break;
    }
    if (time() >= seekTarget_ - half) seekTarget_ = -1;
    clock_ = time();
    return {};
  }
  if (!playing_) return {};
  clock_ += wallSeconds;
  sinceDrop_ += wallSeconds;
  if (clock_ >= time() + frameLength() - 1e-9) {
    if (Status s = Advance(time() + frameLength()); !s.ok()) return s;
    // Still more than a frame behind: drop the debt (slower than real time).
    if (clock_ > time() + frameLength()) {
      clock_ = time();
      sinceDrop_ = 0;
    }
  }
  if (time() >= duration() - half) playing_ = false;
  return {};
}

draw::DrawList ScenePlayer::Frame() const {
  draw::DrawList list = loaded_->staticList;
  if (sim_) sim_->AddToDrawList(list);
  return list;
}

size_t ScenePlayer::particles() const {
  return sim_ ? sim_->Count() : 0;
}

size_t TrianglesOf(const draw::DrawList& list) {
  size_t n = 0;
  for (const draw::MeshDraw& d : list.meshes)
    if (d.mesh) n += d.mesh->triangleCount() * d.instances.size();
  return n;
}

}  // namespace sylva::app
