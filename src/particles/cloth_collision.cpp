#include "particles/cloth_collision.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace sylva::particles::clothcontact {
namespace {

// Coulomb friction on a tangential displacement t against a normal
// displacement depth: static within mu depth, else kinetic.
Vec3 FrictionTaken(const Vec3& t, double mu, double depth) {
  const double len = t.norm();
  const double limit = mu * depth;
  if (len <= limit) return t;
  return t * (limit / len);
}

}  // namespace

const Collider* Collide(const std::vector<Collider>& colliders, const std::vector<double>& radii,
                        const Vec3& p, Vec3& x) {
  const Collider* touched = nullptr;
  Vec3 a = p;
  for (int k = 0; k < 4; ++k) {
    Contact best;
    best.s = 2;
    const Collider* hit = nullptr;
    for (size_t j = 0; j < colliders.size(); ++j) {
      Contact ct;
      if (colliders[j].Intersect(a, x, &ct, radii[j]) && ct.s < best.s) {
        best = ct;
        hit = &colliders[j];
      }
    }
    if (!hit) break;
    touched = hit;
    const Vec3& n = best.normal;
    const double depth = n.dot(best.point - x);
    if (!(depth > 0)) break;  // the path touched the surface but ends outside it
    Vec3 y = x + depth * n;   // back onto the contact's tangent plane
    const Vec3 moved = y - p;
    const Vec3 t = moved - n.dot(moved) * n;  // the substep's tangential motion
    y -= hit->response == Response::kStick ? t : FrictionTaken(t, hit->friction, depth);
    x = y;
    a = best.point;
  }
  if (!touched) return nullptr;
  for (size_t k = 0; k < colliders.size(); ++k) {  // never left inside a solid
    Vec3 sp, sn;
    if (colliders[k].Project(x, &sp, &sn, radii[k])) x = sp;
  }
  return touched;
}

SelfCollision::SelfCollision(std::vector<Vec3> rest, double thickness, double friction)
    : rest_(std::move(rest)), thickness_(thickness), friction_(friction) {}

size_t SelfCollision::Pass(ThreadPool* pool, const Vec3* prev, const Vec3* x, const double* w,
                           std::vector<Vec3>& dx) {
  const size_t n = rest_.size();
  dx.assign(n, Vec3::Zero());
  grid_.Build(x, n, thickness_, pool);
  const double t = thickness_, t2 = t * t;
  std::atomic<size_t> pushed{0};
  ForRanges(pool, n, BalancedGrain(pool, n, 256, 4096), [&](size_t b, size_t e) {
    size_t count = 0;
    for (size_t i = b; i < e; ++i) {
      if (w[i] == 0) continue;
      Vec3 sum = Vec3::Zero();
      int k = 0;
      grid_.ForEachNeighbour(x, i, t, [&](size_t j) {
        const Vec3 d = x[i] - x[j];
        const double d2 = d.squaredNorm();
        if (!(d2 < t2) || !(d2 > 0)) return;                    // coincident: no direction to push
        if ((rest_[i] - rest_[j]).squaredNorm() <= t2) return;  // neighbours at rest
        const double len = std::sqrt(d2);
        const Vec3 dir = d / len;
        const double share = w[i] / (w[i] + w[j]);
        const double depth = t - len;
        Vec3 push = share * depth * dir;
        if (friction_ > 0) {
          const Vec3 rel = (x[i] - prev[i]) - (x[j] - prev[j]);
          const Vec3 tang = rel - dir.dot(rel) * dir;
          push -= share * FrictionTaken(tang, friction_, depth);
        }
        sum += push;
        ++k;
      });
      if (k == 0) continue;
      dx[i] = sum / double(k);
      ++count;
    }
    pushed.fetch_add(count, std::memory_order_relaxed);
  });
  return pushed.load();
}

}  // namespace sylva::particles::clothcontact
