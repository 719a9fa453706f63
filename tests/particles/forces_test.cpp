// Drift, noise wind, grid fields, penalty constraints and avoidance.
#include "particles/forces.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "particles/helpers.h"

#include "particles/flocking.h"

namespace sylva::particles {
namespace {

TEST(NoiseWind, IsDivergenceFreeSmoothAndHasItsSpeed) {
  NoiseWindDef def;
  def.speed = 2;
  def.scale = 0.5;
  def.frequency = 1;
  const auto windOwner = testing::Made(NoiseWind::Create(def));
  const NoiseWind& wind = *windOwner;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-3, 3);
  const double e = 1e-5;
  double worstDiv = 0, gradScale = 0, ms = 0;
  const int N = 2000;
  for (int k = 0; k < N; ++k) {
    const Vec3 x(u(rng), u(rng), u(rng));
    const double t = u(rng);
    double div = 0;
    for (int a = 0; a < 3; ++a) {
      Vec3 d = Vec3::Zero();
      d[a] = e;
      const Vec3 g = (wind.Velocity(x + d, t) - wind.Velocity(x - d, t)) / (2 * e);
      div += g[a];
      gradScale = std::max(gradScale, g.cwiseAbs().maxCoeff());
    }
    worstDiv = std::max(worstDiv, std::abs(div));
    ms += wind.Velocity(x, t).squaredNorm();
  }
  // Central differences are exact to O(e^2 |u'''|): far below the gradient.
  EXPECT_LT(worstDiv, 1e-6 * gradScale)
      << "divergence up to " << worstDiv << " against gradients of " << gradScale;
  EXPECT_GT(gradScale, 1) << "the field must vary";
  EXPECT_NEAR(std::sqrt(ms / N), 2, 0.4) << "RMS speed";
}

TEST(NoiseWind, CarriesParticlesAtTheWindSpeed) {
  NoiseWindDef def;
  def.mean = Vec3(3, 0, 0);
  def.speed = 0;  // uniform wind
  def.drag = 2;
  System s;
  s.state.Add(Vec3::Zero(), Vec3::Zero(), 1);
  s.AddForce(testing::Made(NoiseWind::Create(def)));
  for (int i = 0; i < 2000; ++i) STEP_OK(s, 1e-3, Integrator::kRK4);
  // v(t) = 3 (1 - e^{-2t}).
  EXPECT_NEAR(s.state.velocity[0].x(), 3 * (1 - std::exp(-4.0)), 1e-9);
}

TEST(RandomDrift, HasItsVarianceZeroMeanAndRepeats) {
  auto run = [](int threads) {
    System s(threads);
    for (int i = 0; i < 20000; ++i) s.state.Add(Vec3::Zero(), Vec3::Zero(), 1);
    s.AddForce(std::make_shared<RandomDrift>(0.5, 7));
    if (!s.Step(0.1, Integrator::kSymplecticEuler).ok()) ADD_FAILURE();
    return std::make_pair(s.state.velocity, s.Hash());
  };
  auto [v, h1] = run(1);
  const uint64_t h2 = run(2).second;
  EXPECT_EQ(h1, h2) << "drift must not depend on threads";
  Vec3 mean = Vec3::Zero();
  double var = 0;
  for (const Vec3& x : v) mean += x / 0.1;  // v = h f / m
  mean /= double(v.size());
  for (const Vec3& x : v) var += (x / 0.1 - mean).squaredNorm();
  var /= 3.0 * double(v.size());
  EXPECT_LT(mean.norm(), 0.02) << "mean force " << mean.transpose();
  EXPECT_NEAR(std::sqrt(var), 0.5, 0.01) << "sigma " << std::sqrt(var);
}

TEST(FieldGrid, TrilinearReproducesALinearFieldAndIsZeroOutside) {
  auto linear = [](const Vec3& x) {
    return Vec3(1 + 2 * x.x() - x.y(), 3 * x.z(), x.x() + x.y() + x.z());
  };
  const Vec3 lo(-1, 0, 2), hi(3, 1, 5);
  const std::array<int, 3> n = {5, 3, 4};
  std::vector<Vec3> samples;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 t(double(i) / (n[0] - 1), double(j) / (n[1] - 1), double(k) / (n[2] - 1));
        samples.push_back(linear(lo + t.cwiseProduct(hi - lo)));
      }
  const auto fieldOwner = testing::Made(FieldGrid::Create(lo, hi, n, samples));
  const auto clampedOwner = testing::Made(FieldGrid::Create(lo, hi, n, samples, true));
  const FieldGrid &field = *fieldOwner, &clamped = *clampedOwner;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 x = lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
    worst = std::max(worst, (field.At(x) - linear(x)).norm());
  }
  EXPECT_LT(worst, 1e-12) << "interpolation error " << worst;
  EXPECT_EQ(field.At(Vec3(10, 0.5, 3)), Vec3::Zero());
  EXPECT_LT((clamped.At(Vec3(10, 0.5, 3)) - linear(Vec3(3, 0.5, 3))).norm(), 1e-12);
  // As a force: f = m a.
  ParticleState s;
  s.Add(Vec3(0, 0.5, 3), Vec3::Zero(), 2);
  Vec3 f = Vec3::Zero();
  field.Accumulate(s, s.position.data(), s.velocity.data(), &f);
  EXPECT_LT((f - 2 * linear(Vec3(0, 0.5, 3))).norm(), 1e-12);
}

TEST(Penalty, AnchorSettlesAtTheStaticExtension) {
  for (Integrator in : {Integrator::kRK4, Integrator::kImplicitEuler}) {
    System s;
    s.state.Add(Vec3(0, 0, 0), Vec3::Zero(), 2);
    auto pen = std::make_shared<Penalty>();
    pen->Anchor(0, Vec3(0, 0, 0), 400, 20);
    s.AddForce(pen);
    s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
    for (int i = 0; i < 5000; ++i) STEP_OK(s, 1e-3, in);
    EXPECT_NEAR(s.state.position[0].y(), -2 * 9.81 / 400, 1e-9) << "integrator " << int(in);
  }
}

TEST(Penalty, KeepsADistanceAndStaysOnASurface) {
  System s;
  s.state.Add(Vec3(0, 1.2, 0), Vec3(0.5, 0, 0), 1);  // orbits on the unit sphere
  s.state.Add(Vec3(3, 0, 0), Vec3(0, 0, 0.3), 1);    // a pair 0.8 apart, rest 0.5
  s.state.Add(Vec3(3.8, 0, 0), Vec3(0, 0, -0.3), 1);
  auto pen = std::make_shared<Penalty>();
  pen->OnSphere(0, Vec3::Zero(), 1, 1e4, 200);
  pen->Distance(1, 2, 0.5, 1e4, 200);
  s.AddForce(pen);
  for (int i = 0; i < 20000; ++i) STEP_OK(s, 1e-4, Integrator::kRK4);
  EXPECT_NEAR(s.state.position[0].norm(), 1, 1e-3) << "on the sphere";
  EXPECT_NEAR((s.state.position[1] - s.state.position[2]).norm(), 0.5, 1e-3) << "at the distance";
  const Vec3 p = s.state.velocity[1] + s.state.velocity[2];
  EXPECT_LT(p.norm(), 1e-9) << "the pair's momentum";
  auto plane = std::make_shared<Penalty>();
  System q;
  q.state.Add(Vec3(0, 2, 0), Vec3(1, 0, 0), 1);
  plane->OnPlane(0, Vec3(0, 1, 0), Vec3(0, 1, 0), 1e3, 60);
  q.AddForce(plane);
  for (int i = 0; i < 5000; ++i) STEP_OK(q, 1e-3, Integrator::kSymplecticEuler);
  EXPECT_NEAR(q.state.position[0].y(), 1, 1e-6) << "pulled onto the plane y = 1";
  EXPECT_NEAR(q.state.velocity[0].x(), 1, 1e-12) << "free along it";
}

TEST(Flocking, AvoidKeepsTheFlockOutOfAnObstacle) {
  System s;
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) s.state.Add(Vec3(-6 + u(rng), u(rng), u(rng)), Vec3(1, 0, 0), 1);
  FlockingDef def;
  def.radius = 0.8;
  def.cohesion = 0.5;
  def.separation = 0.5;
  def.alignment = 0.5;
  def.seek = 1;
  def.target = Vec3(6, 0, 0);
  def.avoid = 8;
  def.avoidDistance = 1;
  def.obstacles = {{Vec3::Zero(), 1.5}};
  s.AddForce(testing::Made(Flocking::Create(def)));
  s.AddForce(std::make_shared<Drag>(0.5));
  double closest = 1e9;
  for (int i = 0; i < 3000; ++i) {
    STEP_OK(s, 1.0 / 120, Integrator::kSymplecticEuler);
    for (const Vec3& p : s.state.position) closest = std::min(closest, p.norm());
  }
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : s.state.position) centre += p / 200.0;
  EXPECT_GT(closest, 1.5) << "a boid came within " << closest
                          << " of the obstacle's centre (radius 1.5)";
  EXPECT_GT(centre.x(), 3) << "the flock got past it to the target; centre " << centre.transpose();
}

}  // namespace
}  // namespace sylva::particles
