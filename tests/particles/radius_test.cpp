// A particle's radius in every collider: its centre stays at least its
// radius from the surface (plane, sphere, box, polygon, triangle mesh,
// rough terrain, capsules), in System and BulkSystem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "helpers.h"
#include "particles/bulk.h"
#include "particles/capsules.h"
#include "particles/collider.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

using testing::Made;

Vec3 ClosestOnSegment(const Vec3& a, const Vec3& b, const Vec3& x) {
  const Vec3 e = b - a;
  const double t = std::clamp(e.dot(x - a) / e.squaredNorm(), 0.0, 1.0);
  return a + t * e;
}

// Distance from x to the triangle (v0, v1, v2).
double TriangleDistance(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& x) {
  const Vec3 n = (v1 - v0).cross(v2 - v0).normalized();
  const Vec3 foot = x - n.dot(x - v0) * n;
  const bool inside = (v1 - v0).cross(foot - v0).dot(n) >= 0 &&
                      (v2 - v1).cross(foot - v1).dot(n) >= 0 &&
                      (v0 - v2).cross(foot - v2).dot(n) >= 0;
  if (inside) return std::abs(n.dot(x - v0));
  double d = HUGE_VAL;
  for (const auto& [a, b] : {std::pair{v0, v1}, std::pair{v1, v2}, std::pair{v2, v0}})
    d = std::min(d, (x - ClosestOnSegment(a, b, x)).norm());
  return d;
}

struct Case {
  std::string name;
  Collider collider;
  std::function<double(const Vec3&)> distance;  // from the surface, >= 0 outside the solid
  Vec3 lo, hi;                                  // where particles start
};

// A rough height field over [-2, 2]^2 (random heights up to 0.6 m, 12 x 12
// cells): ridges and valleys whose edges a ball meets before the faces.
struct Terrain {
  std::vector<Vec3> v;
  std::vector<std::array<uint32_t, 3>> t;
};
Terrain RoughTerrain() {
  Terrain g;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> hgt(0, 0.6);
  const int n = 12;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) g.v.push_back(Vec3(-2 + 4.0 * i / n, hgt(rng), -2 + 4.0 * j / n));
  auto at = [&](int i, int j) { return uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      g.t.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
      g.t.push_back({at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
    }
  return g;
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  const Vec3 up(0, 1, 0);
  cases.push_back({"plane", Collider::Plane({0, 0, 0}, up), [](const Vec3& x) { return x.y(); },
                   Vec3(-1, 0.5, -1), Vec3(1, 2, 1)});
  cases.push_back({"sphere", Collider::Sphere({0, 0, 0}, 1),
                   [](const Vec3& x) { return x.norm() - 1; }, Vec3(-0.7, 1.5, -0.7),
                   Vec3(0.7, 2.5, 0.7)});
  cases.push_back({"bowl", Collider::Sphere({0, 0, 0}, 1, true),
                   [](const Vec3& x) { return 1 - x.norm(); }, Vec3(-0.4, -0.3, -0.4),
                   Vec3(0.4, 0.3, 0.4)});
  cases.push_back({"box", Collider::Box({-1, -1, -1}, {1, 0, 1}),
                   [](const Vec3& x) {
                     const Vec3 c = x.cwiseMax(Vec3(-1, -1, -1)).cwiseMin(Vec3(1, 0, 1));
                     return (x - c).norm();
                   },
                   Vec3(-1.3, 0.5, -1.3), Vec3(1.3, 2, 1.3)});
  cases.push_back({"container", Collider::Box({-1, -1, -1}, {1, 1, 1}, true),
                   [](const Vec3& x) {
                     return std::min((x - Vec3(-1, -1, -1)).minCoeff(),
                                     (Vec3(1, 1, 1) - x).minCoeff());
                   },
                   Vec3(-0.7, -0.7, -0.7), Vec3(0.7, 0.7, 0.7)});
  const Vec3 q0(-1, 0, -1), q1(-1, 0, 1), q2(1, 0, 1), q3(1, 0, -1);
  cases.push_back({"polygon", Collider::Polygon({q0, q1, q2, q3}),
                   [=](const Vec3& x) {
                     return std::min(TriangleDistance(q0, q1, q2, x),
                                     TriangleDistance(q0, q2, q3, x));
                   },
                   Vec3(-1.2, 0.3, -1.2), Vec3(1.2, 2, 1.2)});
  auto terrain = std::make_shared<Terrain>(RoughTerrain());
  cases.push_back({"terrain", Collider::Mesh(std::make_shared<TriangleBvh>(terrain->v, terrain->t)),
                   [terrain](const Vec3& x) {
                     double d = HUGE_VAL;
                     for (const auto& t : terrain->t)
                       d = std::min(d, TriangleDistance(terrain->v[t[0]], terrain->v[t[1]],
                                                        terrain->v[t[2]], x));
                     return d;
                   },
                   Vec3(-1.8, 1, -1.8), Vec3(1.8, 2.5, 1.8)});
  std::vector<Capsule> caps = {{Vec3(-1, 0, 0), Vec3(1, 0, 0), 0.15},
                               {Vec3(1, 0, 0), Vec3(1.5, 0.8, 0.3), 0.1},
                               {Vec3(-1, 0, -0.6), Vec3(1, 0.2, 0.6), 0.12}};
  cases.push_back({"capsules", Collider::Capsules(std::make_shared<CapsuleBvh>(caps)),
                   [caps](const Vec3& x) {
                     double d = HUGE_VAL;
                     for (const Capsule& c : caps)
                       d = std::min(d, (x - ClosestOnSegment(c.a, c.b, x)).norm() - c.radius);
                     return d;
                   },
                   Vec3(-1, 0.5, -0.5), Vec3(1.4, 1.5, 0.5)});
  return cases;
}

constexpr double kRadius = 0.1;

// Particles of radius kRadius dropped on each collider for 3 s at 60 Hz
// (restitution 0.4, friction 0.3, a random sideways throw); the smallest
// distance - radius seen over every step and particle.
template <typename Sys, typename StepFn, typename PosFn>
double Clearance(Sys& sys, const Case& c, StepFn step, PosFn position, size_t count) {
  double worst = HUGE_VAL;
  for (int s = 0; s < 180; ++s) {
    if (!step()) return -HUGE_VAL;
    for (size_t i = 0; i < count; ++i)
      worst = std::min(worst, c.distance(position(sys, i)) - kRadius);
  }
  return worst;
}

TEST(ContactRadius, TheCentreStaysItsRadiusFromEveryCollider) {
  for (const Case& c : Cases()) {
    System sys(1);
    sys.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
    ASSERT_OK(sys.AddCollider(Collider(c.collider).Restitution(0.4).Friction(0.3)));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 200; ++i) {
      Vec3 p;
      do {  // starts clear of the surface
        p = c.lo + (c.hi - c.lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
      } while (c.distance(p) < 1.5 * kRadius);
      sys.state.Add(p, Vec3(u(rng) - 0.5, 0, u(rng) - 0.5) * 2);
      sys.state.radius.back() = float(kRadius);
    }
    Status status;
    const double worst = Clearance(
        sys, c,
        [&] {
          status = sys.Step(1.0 / 60, Integrator::kSymplecticEuler);
          return status.ok();
        },
        [](System& s, size_t i) { return s.state.position[i]; }, sys.state.size());
    ASSERT_TRUE(status.ok()) << c.name << ": " << status.error().message;
    EXPECT_GE(worst, -1e-9) << c.name << ": a centre came " << -worst << " m inside its radius "
                            << kRadius << " of the surface";
  }
}

TEST(ContactRadius, BulkCentreStaysItsRadiusFromEveryCollider) {
  for (const Case& c : Cases()) {
    BulkSystem sys(1);
    sys.fields.gravity = Vec3(0, -9.81, 0);
    ASSERT_OK(sys.AddCollider(Collider(c.collider).Restitution(0.4).Friction(0.3)));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 200; ++i) {
      Vec3 p;
      do {  // starts clear of the surface
        p = c.lo + (c.hi - c.lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
      } while (c.distance(p) < 1.5 * kRadius);
      sys.state.Add(p, Vec3(u(rng) - 0.5, 0, u(rng) - 0.5) * 2);
      sys.state.radius.back() = float(kRadius);
    }
    Status status;
    const double worst = Clearance(
        sys, c,
        [&] {
          status = sys.Step(1.0 / 60);
          return status.ok();
        },
        [](BulkSystem& s, size_t i) { return s.state.position(i); }, sys.state.size());
    ASSERT_TRUE(status.ok()) << c.name << ": " << status.error().message;
    // Single precision: positions of about 2 m round to 1.2e-7.
    EXPECT_GE(worst, -1e-6) << c.name << ": a centre came " << -worst << " m inside its radius "
                            << kRadius << " of the surface";
  }
}

// Each particle's own radius counts: balls of 0.05 and 0.2 m rest on a
// plane at their own heights.
TEST(ContactRadius, EachParticleRestsAtItsOwnRadius) {
  System sys(1);
  sys.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  ASSERT_OK(sys.AddCollider(Collider::Plane({0, 0, 0}, {0, 1, 0}).Restitution(0)));
  const float radii[] = {0.05f, 0.2f, 0};
  for (int i = 0; i < 3; ++i) {
    sys.state.Add(Vec3(i, 1, 0), Vec3::Zero());
    sys.state.radius.back() = radii[i];
  }
  for (int s = 0; s < 120; ++s) STEP_OK(sys, 1.0 / 60, Integrator::kSymplecticEuler);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(sys.state.position[size_t(i)].y(), radii[i], 1e-9)
        << "particle of radius " << radii[i]
        << " rests at y = " << sys.state.position[size_t(i)].y();
    EXPECT_LT(sys.state.velocity[size_t(i)].norm(), 1e-6)
        << "particle of radius " << radii[i] << " still moves at "
        << sys.state.velocity[size_t(i)].norm() << " m/s";
  }
}

}  // namespace
}  // namespace sylva::particles

namespace sylva::particles {
namespace {

// The mesh collider's broad phase (MayHit: TriangleBvh::Near, with its
// columns' height bound) and its grid for short paths: 20,000 random short
// paths through and over a rough terrain, as points and as balls of 0.05 m,
// the terrain lying flat (its thin axis y) and standing as a wall (its
// coordinates rotated, so that the thin axis is x, then z). MayHit never
// rejects a path that hits, Intersect finds the first hit brute force
// finds over single triangles, and only the paths near the triangles go to
// the exact test (every path did before).
TEST(MeshBroadPhase, OnlyPathsNearTheTrianglesGoToTheExactTest) {
  for (int turn = 0; turn < 3; ++turn) {
    // (x, y, z) -> the same coordinates turned `turn` places.
    auto turned = [turn](const Vec3& p) {
      return Vec3(p[(3 - turn) % 3], p[(4 - turn) % 3], p[(5 - turn) % 3]);
    };
    Terrain g = RoughTerrain();
    for (Vec3& p : g.v) p = turned(p);
    const Collider mesh = Collider::Mesh(std::make_shared<TriangleBvh>(g.v, g.t));
    std::vector<Collider> single;
    for (const auto& t : g.t)
      single.push_back(Collider::Mesh(
          std::make_shared<TriangleBvh>(std::vector<Vec3>{g.v[t[0]], g.v[t[1]], g.v[t[2]]},
                                        std::vector<std::array<uint32_t, 3>>{{0, 1, 2}})));
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1), step(-0.08, 0.08);
    for (double r : {0.0, 0.05}) {
      int near = 0, hits = 0, missed = 0, wrong = 0;
      double worst = 0;
      for (int k = 0; k < (turn == 0 ? 20000 : 5000); ++k) {
        const Vec3 a = turned(Vec3(-2 + 4 * u(rng), -0.2 + 2.2 * u(rng), -2 + 4 * u(rng)));
        const Vec3 b = a + Vec3(step(rng), step(rng), step(rng));
        double brute = 2;
        for (const Collider& c : single) {
          Contact ct;
          if (c.Intersect(a, b, &ct, r)) brute = std::min(brute, ct.s);
        }
        const bool may = mesh.MayHit(a, b, r);
        near += may;
        Contact ct;
        const bool hit = mesh.Intersect(a, b, &ct, r);
        hits += brute <= 1;
        if (brute <= 1 && !may) ++missed;
        if (hit != (brute <= 1)) {
          ++wrong;
        } else if (hit) {
          worst = std::max(worst, std::abs(ct.s - brute));
        }
      }
      const int paths = turn == 0 ? 20000 : 5000;
      EXPECT_EQ(missed, 0) << "turn " << turn << ", r = " << r
                           << ": paths that hit but MayHit rejected: " << missed;
      EXPECT_EQ(wrong, 0) << "turn " << turn << ", r = " << r
                          << ": paths where Intersect and brute force disagree";
      EXPECT_LT(worst, 1e-12) << "turn " << turn << ", r = " << r
                              << ": first hit differs from brute force by " << worst;
      EXPECT_LT(near, paths / 2) << "turn " << turn << ", r = " << r << ": " << near << " of "
                                 << paths << " paths (" << hits << " hit) went to the exact test";
    }
  }
}

// A NaN in any component of a path's start or end, or in its radius, is
// clear of nothing: Near says the path may hit (before, a NaN across the
// terrain's columns was cast to a column index and read far outside them).
TEST(MeshBroadPhase, APathWithANaNIsNeverScreenedOut) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Terrain g = RoughTerrain();
  const TriangleBvh mesh(g.v, g.t);
  const Vec3 a(0.1, 0.3, 0.1), b(0.12, 0.29, 0.11);
  for (int k = 0; k < 7; ++k) {
    Vec3 from = a, to = b;
    double r = 0.01;
    if (k < 3)
      from[k] = nan;
    else if (k < 6)
      to[k - 3] = nan;
    else
      r = nan;
    EXPECT_FALSE(mesh.Clear(from, to, r)) << "NaN in "
                                          << (k < 3   ? "a"
                                              : k < 6 ? "b"
                                                      : "r")
                                          << (k < 6 ? "[" + std::to_string(k % 3) + "]" : "");
    EXPECT_TRUE(mesh.Near(from, to, r)) << "NaN in "
                                        << (k < 3   ? "a"
                                            : k < 6 ? "b"
                                                    : "r")
                                        << (k < 6 ? "[" + std::to_string(k % 3) + "]" : "");
  }
}

}  // namespace
}  // namespace sylva::particles
