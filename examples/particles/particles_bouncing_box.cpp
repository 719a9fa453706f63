// The chapter's simple particle system (Angel & Shreiner 9.4): particles in
// the cube [-1,1]^3 with random velocities, under gravity, bouncing off the
// six faces with a coefficient of restitution. Runs headless, prints what
// it did, and draws the last frame through Sylva's point pipeline.
//
//   particles_bouncing_box [COUNT] [SECONDS] [OUT.png]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "draw/convert.h"
#include "particles/system.h"
#include "render/headless_context.h"
#include "render/renderer.h"

using namespace sylva;

int main(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 2000;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 3.0;
  const char* out = argc > 3 ? argv[3] : "out/particles_bouncing_box.png";
  if (count < 1 || !(seconds > 0)) {
    std::fprintf(stderr, "usage: particles_bouncing_box [COUNT >= 1] [SECONDS > 0] [OUT.png]\n");
    return 2;
  }
  particles::System sys;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < count; ++i)
    sys.state.Add(Vec3(u(rng), u(rng), u(rng)) * 0.9, Vec3(u(rng), u(rng), u(rng)) * 3);
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.0, 1.0}) {
      particles::Plane p;
      p.point = Vec3::Zero();
      p.point[axis] = side;
      p.normal = Vec3::Zero();
      p.normal[axis] = -side;
      p.restitution = 0.85;
      if (Status st = sys.AddPlane(p); !st.ok()) {
        std::fputs(st.error().Format().c_str(), stderr);
        return 1;
      }
    }
  }
  const double h = 1.0 / 240;
  const double e0 = sys.KineticEnergy();
  int escaped = 0;
  for (int step = 0; step * h < seconds; ++step) {
    if (Status st = sys.Step(h, particles::Integrator::kSymplecticEuler); !st.ok()) {
      std::fputs(st.error().Format().c_str(), stderr);
      return 1;
    }
  }
  double lowest = 1e9;
  for (const Vec3& p : sys.state.position) {
    escaped += p.cwiseAbs().maxCoeff() > 1 + 1e-9;
    lowest = std::min(lowest, p.y());
  }
  std::printf(
      "%d particles, %.2f s in steps of 1/240 s: kinetic energy %.1f J -> %.1f J, "
      "%d outside the box, lowest at y = %.3f\n",
      count, sys.time, e0, sys.KineticEnergy(), escaped, lowest);

  // The last frame, coloured by speed, through the renderer's point pipeline.
  auto context = render::HeadlessContext::Create();
  if (!context) {
    std::fprintf(stderr, "no OpenGL (%s): skipping the picture\n", context.error().message.c_str());
    return escaped ? 1 : 0;
  }
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer || !(*renderer)->Resize(480, 360).ok()) return 1;
  draw::DrawList list;
  list.background = mesh::Srgb(0.08f, 0.08f, 0.1f);
  std::vector<mesh::Vec3f> colors(sys.state.size());
  for (size_t i = 0; i < sys.state.size(); ++i) {
    const float speed = float(std::min(sys.state.velocity[i].norm() / 6.0, 1.0));
    colors[i] = mesh::Srgb(0.95f, 0.35f + 0.6f * speed, 0.15f + 0.5f * (1 - speed));
  }
  draw::PointStyle style;
  style.size = 0.035f;
  auto points = draw::PointSprites(sys.state.position, style, colors);
  if (!points) {
    std::fputs(points.error().Format().c_str(), stderr);
    return 1;
  }
  list.sprites.push_back(std::move(*points));
  // The cube's edges as lines.
  draw::Lines& edges = list.lines.emplace_back();
  for (int a = 0; a < 8; ++a) {
    for (int bit = 0; bit < 3; ++bit) {
      const int b = a | (1 << bit);
      if (b == a) continue;
      auto corner = [](int k) {
        return mesh::Vec3f(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
      };
      edges.points.push_back(corner(a));
      edges.points.push_back(corner(b));
      edges.colors.push_back(mesh::Srgb(0.6f, 0.6f, 0.65f));
      edges.colors.push_back(mesh::Srgb(0.6f, 0.6f, 0.65f));
    }
  }
  if (Status st = (*renderer)->Draw(
          list, render::Camera::Frame(Vec3(-1, -1, -1), Vec3(1, 1, 1), 480.0 / 360, 30, 20, false));
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
  return escaped ? 1 : 0;
}
