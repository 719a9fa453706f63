// Fireworks (Angel & Shreiner 9.4: colour changing with time and random
// lifetimes): rockets rise and, when their lifetime ends, burst into sparks
// whose colour fades with age; some sparks burst again. Runs headless,
// prints what it did, and draws one frame through the point pipeline.
//
//   particles_fireworks [SECONDS] [OUT.png]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "draw/convert.h"
#include "particles/emitter.h"
#include "render/headless_context.h"
#include "render/renderer.h"

using namespace sylva;
using particles::EmitterDef;

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 2.6;
  const char* out = argc > 2 ? argv[2] : "out/particles_fireworks.png";
  if (!(seconds > 0)) {
    std::fprintf(stderr, "usage: particles_fireworks [SECONDS > 0] [OUT.png]\n");
    return 2;
  }
  particles::System sys;
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  sys.AddForce(std::make_shared<particles::Drag>(0.6));
  // What each particle is: a rocket, a spark, or a spark that bursts again.
  enum Kind { kRocket, kSpark, kBursting };
  std::map<uint32_t, Kind> kind;
  std::map<uint32_t, particles::Emitter> emitterOf;
  // Colours are linear inside Sylva; these were picked in sRGB.
  const Vec3f palette[4] = {mesh::Srgb(1.0f, 0.35f, 0.2f), mesh::Srgb(0.3f, 0.7f, 1.0f),
                            mesh::Srgb(1.0f, 0.85f, 0.3f), mesh::Srgb(0.7f, 1.0f, 0.4f)};

  EmitterDef rockets;
  rockets.rate = 3;
  rockets.position = Vec3(0, 0, 0);
  rockets.positionRadius = 2;
  rockets.velocity = Vec3(0, 16, 0);
  rockets.velocitySpread = 2.5;
  rockets.lifetime = 1.0;
  rockets.lifetimeJitter = 0.2;
  rockets.colorStart = rockets.colorEnd = mesh::Srgb(1, 0.9f, 0.7f);
  rockets.seed = 2026;
  auto made = particles::Emitter::Create(rockets);
  if (!made) {
    std::fputs(made.error().Format().c_str(), stderr);
    return 1;
  }
  particles::Emitter& launcher = *made;
  int bursts = 0, sparks = 0;
  uint32_t stream = 1;
  bool failed = false;
  auto burst = [&](const Vec3& at, const Vec3& v, int n, double speed, bool again) {
    EmitterDef d;
    d.position = at;
    d.velocity = v * 0.3;
    d.velocitySpread = speed;
    d.lifetime = again ? 0.7 : 1.3;
    d.lifetimeJitter = 0.3;
    d.mass = 0.5;  // drag decelerates sparks at 0.6 / 0.5 = 1.2 per second
    d.colorStart = palette[stream % 4];
    d.colorEnd = mesh::Srgb(0.25f, 0.05f, 0.05f);
    d.seed = 2026;
    d.stream = stream++;
    auto e = particles::Emitter::Create(d);
    if (!e) {  // every def here is in range; a bad one is reported and ends the run
      std::fputs(e.error().Format().c_str(), stderr);
      failed = true;
      return;
    }
    const uint32_t first = sys.state.nextId;
    e->Burst(sys.state, n);
    for (uint32_t id = first; id < sys.state.nextId; ++id) {
      kind[id] = again && id % 9 == 0 ? kBursting : kSpark;
      emitterOf.emplace(id, *e);
    }
    ++bursts;
    sparks += n;
  };
  const double h = 1.0 / 120;
  for (int step = 0; step * h < seconds; ++step) {
    if (sys.time < seconds * 0.6) {
      const uint32_t first = sys.state.nextId;
      if (Status st = launcher.Emit(sys.state, h); !st.ok()) {
        std::fputs(st.error().Format().c_str(), stderr);
        return 1;
      }
      for (uint32_t id = first; id < sys.state.nextId; ++id) kind[id] = kRocket;
    }
    if (Status st = sys.Step(h, particles::Integrator::kSymplecticEuler); !st.ok()) {
      std::fputs(st.error().Format().c_str(), stderr);
      return 1;
    }
    // Colour over age; rockets and bursting sparks that die burst.
    for (size_t i = 0; i < sys.state.size(); ++i) {
      const uint32_t id = sys.state.id[i];
      auto e = emitterOf.find(id);
      if (e != emitterOf.end())
        sys.state.color[i] = e->second.ColorAt(sys.state.age[i], sys.state.lifetime[i]);
      if (sys.state.age[i] >= sys.state.lifetime[i]) {
        if (kind[id] == kRocket)
          burst(sys.state.position[i], sys.state.velocity[i], 160, 7.0, true);
        if (kind[id] == kBursting)
          burst(sys.state.position[i], sys.state.velocity[i], 25, 3.0, false);
      }
    }
    particles::RemoveDead(sys.state);
    if (failed) return 1;
  }
  std::printf("%.2f s: %d bursts, %d sparks made, %zu particles alive\n", sys.time, bursts, sparks,
              sys.state.size());

  auto context = render::HeadlessContext::Create();
  if (!context) {
    std::fprintf(stderr, "no OpenGL (%s): skipping the picture\n", context.error().message.c_str());
    return 0;
  }
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer || !(*renderer)->Resize(480, 360).ok()) return 1;
  // Drawn sizes: rockets larger than sparks (radii, half the diameters).
  std::vector<float> radii(sys.state.size());
  Vec3 lo = sys.state.size() ? sys.state.position[0] : Vec3::Zero(), hi = lo;
  for (size_t i = 0; i < sys.state.size(); ++i) {
    radii[i] = kind[sys.state.id[i]] == kRocket ? 0.06f : 0.035f;
    lo = lo.cwiseMin(sys.state.position[i]);
    hi = hi.cwiseMax(sys.state.position[i]);
  }
  draw::DrawList list;
  list.background = mesh::Srgb(0.03f, 0.03f, 0.07f);
  auto points = draw::PointSprites(sys.state.position, {}, sys.state.color, radii);
  if (!points) {
    std::fputs(points.error().Format().c_str(), stderr);
    return 1;
  }
  list.sprites.push_back(std::move(*points));
  if (Status st = (*renderer)->Draw(list, render::Camera::Frame(lo, hi, 480.0 / 360, 0, 5, false));
      !st.ok()) {
    std::fputs(st.error().Format().c_str(), stderr);
    return 1;
  }
  if (std::error_code ec; !std::filesystem::path(out).parent_path().empty()) {
    std::filesystem::create_directories(std::filesystem::path(out).parent_path(),
                                        ec);  // out/ by default
  }
  if (Status s = render::WritePng((*renderer)->ReadPixels(), out); !s.ok()) {
    std::fprintf(stderr, "%s", s.error().Format().c_str());
    return 1;
  }
  std::printf("wrote %s\n", out);
  return bursts > 0 ? 0 : 1;
}
