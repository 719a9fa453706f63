// A flock (Reynolds 1987; Angel & Shreiner 9.4): boids with cohesion,
// separation and alignment over grid neighbours, seeking a target that
// circles a spherical obstacle they avoid. Runs headless on two threads,
// prints the order parameter and the closest approach to the obstacle, and
// draws the last frame through Sylva's point pipeline.
//
//   particles_flock [COUNT] [SECONDS] [OUT.png]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "draw/convert.h"
#include "particles/flocking.h"
#include "particles/system.h"
#include "render/headless_context.h"
#include "render/renderer.h"

using namespace sylva;

int main(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 3000;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 8.0;
  const char* out = argc > 3 ? argv[3] : "out/particles_flock.png";
  if (count < 1 || !(seconds > 0)) {
    std::fprintf(stderr, "usage: particles_flock [COUNT >= 1] [SECONDS > 0] [OUT.png]\n");
    return 2;
  }
  particles::System sys(0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < count; ++i) {
    sys.state.Add(Vec3(-6 + 2 * u(rng), 2 * u(rng), 2 * u(rng)), Vec3(u(rng), u(rng), u(rng)), 1);
  }
  const Vec3 obstacle(0, 0, 0);
  const double radius = 1.5;
  particles::FlockingDef def;
  def.radius = 0.9;
  def.cohesion = 0.4;
  def.separation = 2.0;
  def.separationRadius = 0.35;
  def.alignment = 1.5;
  def.seek = 0.6;
  def.avoid = 10;
  def.avoidDistance = 1.0;
  def.obstacles = {{obstacle, radius}};
  auto made = particles::Flocking::Create(def);
  if (!made) {
    std::fputs(made.error().Format().c_str(), stderr);
    return 1;
  }
  std::shared_ptr<particles::Flocking> flock = *made;
  sys.AddForce(flock);
  sys.AddForce(std::make_shared<particles::Drag>(0.4));
  const double h = 1.0 / 120;
  const double before = particles::OrderParameter(sys.state);
  double closest = 1e9;
  for (int step = 0; step * h < seconds; ++step) {
    // The target circles the obstacle, 5 units out, once every 8 s.
    const double a = 2 * M_PI * step * h / 8;
    flock->def().target = Vec3(-5 * std::cos(a), 1.5 * std::sin(2 * a), 5 * std::sin(a));
    if (Status st = sys.Step(h, particles::Integrator::kSymplecticEuler); !st.ok()) {
      std::fputs(st.error().Format().c_str(), stderr);
      return 1;
    }
    for (const Vec3& p : sys.state.position)
      closest = std::min(closest, (p - obstacle).norm() - radius);
  }
  const double after = particles::OrderParameter(sys.state);
  std::printf(
      "%d boids, %.1f s on %d threads: order parameter %.2f -> %.2f, closest approach to the "
      "obstacle %.3f\n",
      count, sys.time, sys.threads(), before, after, closest);
  const bool ok = closest > 0;

  auto context = render::HeadlessContext::Create();
  if (!context) {
    std::fprintf(stderr, "no OpenGL (%s): skipping the picture\n", context.error().message.c_str());
    return ok ? 0 : 1;
  }
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer || !(*renderer)->Resize(480, 360).ok()) return 1;
  draw::DrawList list;
  list.background = mesh::Srgb(0.08f, 0.08f, 0.1f);
  std::vector<mesh::Vec3f> colors(sys.state.size());
  for (size_t i = 0; i < sys.state.size(); ++i) {
    const Vec3 v = sys.state.velocity[i].normalized();
    colors[i] = mesh::Srgb(0.55f + 0.45f * float(v.x()), 0.6f + 0.4f * float(v.y()),
                           0.65f + 0.35f * float(v.z()));
  }
  draw::PointStyle style;
  style.size = 0.1f;
  auto boids = draw::PointSprites(sys.state.position, style, colors);
  if (!boids) {
    std::fputs(boids.error().Format().c_str(), stderr);
    return 1;
  }
  list.sprites.push_back(std::move(*boids));
  // The obstacle as a ring of points on three great circles.
  draw::Sprites& batch = list.sprites.emplace_back();
  for (int k = 0; k < 360; ++k) {
    const double t = 2 * M_PI * k / 360;
    for (int c = 0; c < 3; ++c) {
      Vec3 p = Vec3::Zero();
      p[c] = radius * std::cos(t);
      p[(c + 1) % 3] = radius * std::sin(t);
      batch.positions.push_back((obstacle + p).cast<float>());
      batch.sizes.push_back(0.05f);
      batch.colors.push_back(mesh::Srgb(0.9f, 0.3f, 0.2f));
    }
  }
  Vec3 lo = Vec3::Constant(-4.5), hi = Vec3::Constant(4.5);
  if (Status st =
          (*renderer)->Draw(list, render::Camera::Frame(lo, hi, 480.0 / 360, 30, 25, false));
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
