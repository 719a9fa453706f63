// Snow by the hundred thousand: a BulkSystem (single precision, eight
// particles an AVX instruction) fed by an emitter, in a gusting wind, onto
// a ground with friction and a ball that the flakes stick to. Runs
// headless, prints what it did, and draws the last frame through Sylva's
// point pipeline.
//
//   particles_snow [FLAKES] [SECONDS] [OUT.png]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "draw/convert.h"
#include "particles/bulk.h"
#include "particles/emitter.h"
#include "render/headless_context.h"
#include "render/renderer.h"

using namespace sylva;

int main(int argc, char** argv) {
  const int flakes = argc > 1 ? std::atoi(argv[1]) : 200000;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 4.0;
  const char* out = argc > 3 ? argv[3] : "out/particles_snow.png";
  if (flakes < 1 || !(seconds > 0)) {
    std::fprintf(stderr, "usage: particles_snow [FLAKES >= 1] [SECONDS > 0] [OUT.png]\n");
    return 2;
  }
  // Flakes fall at about 1 m/s: light, with strong drag toward the wind.
  particles::EmitterDef def;
  def.rate = flakes / (0.75 * seconds);  // all of them in the first three quarters
  def.position = Vec3(0, 2.5, 0);
  def.positionRadius = 1.6;
  def.velocity = Vec3(0, -0.5, 0);
  def.velocitySpread = 0.3;
  def.mass = 0.002;
  def.lifetime = 1e6;
  auto made = particles::Emitter::Create(def);
  if (!made) {
    std::fputs(made.error().Format().c_str(), stderr);
    return 1;
  }
  particles::Emitter& emitter = *made;
  particles::ParticleState born;

  particles::BulkSystem snow(0);
  snow.state.Reserve(size_t(flakes));
  snow.fields.gravity = Vec3(0, -9.81, 0);
  snow.fields.linearDrag = 0.02;  // terminal speed m g / k = 0.98 m/s
  const Vec3 ballCentre(0.3, 0.4, 0), ground(0, 0, 0);
  const double ballRadius = 0.4;
  for (const particles::Collider& c :
       {particles::Collider::Plane(ground, Vec3(0, 1, 0)).Restitution(0).Friction(0.8),
        particles::Collider::Sphere(ballCentre, ballRadius).Respond(particles::Response::kStick)}) {
    if (Status st = snow.AddCollider(c); !st.ok()) {
      std::fputs(st.error().Format().c_str(), stderr);
      return 1;
    }
  }

  const double h = 1.0 / 120;
  double stepSeconds = 0;
  int steps = 0;
  for (; steps * h < seconds; ++steps) {
    // Gusts: the wind swings across x, slowly.
    snow.fields.wind =
        Vec3(0.6 * std::sin(0.8 * snow.time()), 0, 0.3 * std::cos(0.5 * snow.time()));
    if (int(born.size()) < flakes) {
      const size_t first = born.size();
      if (Status st = emitter.Emit(born, h); !st.ok()) {
        std::fputs(st.error().Format().c_str(), stderr);
        return 1;
      }
      if (int(born.size()) > flakes) {
        // Keep exactly the requested count.
        for (auto* a : {&born.position, &born.velocity}) a->resize(size_t(flakes));
        for (auto* a : {&born.mass, &born.invMass, &born.age, &born.lifetime})
          a->resize(size_t(flakes));
        born.color.resize(size_t(flakes));
        born.radius.resize(size_t(flakes));
        born.id.resize(size_t(flakes));
      }
      snow.Append(born, first);
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (Status st = snow.Step(h); !st.ok()) {
      std::fputs(st.error().Format().c_str(), stderr);
      return 1;
    }
    stepSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  // Where the flakes are: on the ground, stuck to the ball, in the air; none
  // may be closer to the ground or the ball than its radius (a flake is a
  // ball of its radius to the colliders).
  int onGround = 0, onBall = 0, falling = 0, inside = 0;
  for (size_t i = 0; i < snow.state.size(); ++i) {
    const Vec3 p = snow.state.position(i);
    const double r = double(snow.state.radius[i]);
    if (p.y() < r - 1e-6 || (p - ballCentre).norm() < ballRadius + r - 1e-5) ++inside;
    if (snow.state.invMass[i] == 0) {
      ++onBall;
    } else if (p.y() < r + 1e-4 && snow.state.velocity(i).norm() < 1e-6) {
      ++onGround;
    } else {
      ++falling;
    }
  }
  std::printf(
      "%zu flakes, %.2f s in %d steps of 1/120 s (%.2f ms a step on %d threads): "
      "%d resting on the ground, %d stuck to the ball, %d in the air, %d inside a solid\n",
      snow.state.size(), snow.time(), steps, 1e3 * stepSeconds / steps, snow.threads(), onGround,
      onBall, falling, inside);
  const bool ok = inside == 0 && onGround > 0 && onBall > 0 && int(snow.state.size()) == flakes;

  // The last frame: white flakes, the ball as a ring of its silhouette.
  auto context = render::HeadlessContext::Create();
  if (!context) {
    std::fprintf(stderr, "no OpenGL (%s): skipping the picture\n", context.error().message.c_str());
    return ok ? 0 : 1;
  }
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer || !(*renderer)->Resize(480, 360).ok()) return 1;
  draw::DrawList list;
  list.background = mesh::Srgb(0.12f, 0.14f, 0.2f);
  std::vector<mesh::Vec3f> colors(snow.state.size());
  for (size_t i = 0; i < snow.state.size(); ++i) {
    const bool stuck = snow.state.invMass[i] == 0;
    colors[i] = stuck ? mesh::Srgb(0.75f, 0.85f, 1.0f) : mesh::Srgb(0.95f, 0.95f, 0.95f);
  }
  draw::PointStyle style;
  style.size = 0.012f;
  auto points = draw::PointSprites(snow.state.px, snow.state.py, snow.state.pz, style, colors);
  if (!points) {
    std::fputs(points.error().Format().c_str(), stderr);
    return 1;
  }
  list.sprites.push_back(std::move(*points));
  draw::Lines& lines = list.lines.emplace_back();
  for (int k = 0; k < 64; ++k) {
    const double a0 = 2 * M_PI * k / 64, a1 = 2 * M_PI * (k + 1) / 64;
    for (double a : {a0, a1}) {
      lines.points.push_back(
          (ballCentre + ballRadius * Vec3(std::cos(a), std::sin(a), 0)).cast<float>());
      lines.colors.push_back(mesh::Srgb(0.9f, 0.5f, 0.2f));
    }
  }
  for (double x : {-2.0, 2.0}) {  // the ground's edge
    lines.points.push_back(mesh::Vec3f(float(x), 0, -2));
    lines.points.push_back(mesh::Vec3f(float(x), 0, 2));
    lines.points.push_back(mesh::Vec3f(-2, 0, float(x)));
    lines.points.push_back(mesh::Vec3f(2, 0, float(x)));
    for (int c = 0; c < 4; ++c) lines.colors.push_back(mesh::Srgb(0.5f, 0.55f, 0.6f));
  }
  if (Status st = (*renderer)->Draw(
          list, render::Camera::Frame(Vec3(-2, 0, -2), Vec3(2, 3, 2), 480.0 / 360, 25, 15, false));
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
  return ok ? 0 : 1;
}
