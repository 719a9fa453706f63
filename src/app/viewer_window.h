// What the viewer's two modes (a grammar, a scene) share: the window with
// its OpenGL 4.5 context and Dear ImGui, the mouse camera, and a worker
// thread that runs the newest posted job (an overtaken job's result is
// dropped). Internal to the viewer; GLFW types stay in this header's users.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <iosfwd>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "render/camera.h"

struct GLFWwindow;

namespace sylva::app {

// The window, its GL context and Dear ImGui; destroyed in that order.
struct Window {
  GLFWwindow* handle = nullptr;
  ~Window();
};

// Opens a window with an OpenGL 4.5 core context and Dear ImGui on it;
// returns the exit status on failure (message printed).
int OpenWindow(int width, int height, const std::string& title, bool vsync, Window& w,
               std::ostream& err);

// Left drag orbits, right drag pans, the wheel zooms (in parallel
// projection it scales the extent shown): a drag only when its
// button went down off the panel, the wheel only off the panel. Call it
// after ImGui::NewFrame (which decides what the panel wants this frame).
struct MouseCamera {
  double lastX = 0, lastY = 0;
  bool leftDown = false, rightDown = false;    // the buttons at the last update
  bool leftOrbits = false, rightPans = false;  // the drag began off the panel
  void Update(GLFWwindow* window, render::Camera& camera);
};

// Runs `run` on posted jobs, one at a time on its own thread; only the
// newest job matters.
template <class Job, class Result>
class Worker {
 public:
  explicit Worker(std::function<Result(const Job&)> run)
      : run_(std::move(run)), thread_([this] { Loop(); }) {}
  ~Worker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  void Post(Job job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pending_ = std::move(job);
    }
    wake_.notify_all();
  }
  std::optional<Result> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<Result> r = std::move(done_);
    done_.reset();
    return r;
  }
  bool Busy() const { return busy_.load(); }

 private:
  void Loop() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
        if (stop_) return;
        job = std::move(*pending_);
        pending_.reset();
        busy_ = true;
      }
      Result r = run_(job);
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
      if (!pending_) done_ = std::move(r);  // overtaken results are dropped
    }
  }
  std::function<Result(const Job&)> run_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> pending_;
  std::optional<Result> done_;
  std::atomic<bool> busy_{false};
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace sylva::app
