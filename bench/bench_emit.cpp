// Emitting a million particles: one Emit call of rate 1e6 for 1 s into a
// fresh state, per shape; the same spread over 60 frames; into a state
// whose memory is kept; and a frame's births appended to a BulkSystem.
// Items are particles.
//
//   bench_emit --benchmark_min_time=0.2
#include <benchmark/benchmark.h>

#include "particles/bulk.h"
#include "particles/emitter.h"

using namespace sylva;

namespace {

constexpr int kCount = 1'000'000;

// A 128 x 128 grid of quads over [-10, 10]^2 with a bump: 32,768 triangles
// of unequal areas.
std::shared_ptr<particles::EmitterMesh> Terrain() {
  auto m = std::make_shared<particles::EmitterMesh>();
  const int n = 129;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = -10 + 20.0 * i / (n - 1), z = -10 + 20.0 * j / (n - 1);
      m->positions.emplace_back(x, 3 * std::exp(-(x * x + z * z) / 20), z);
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const uint32_t a = uint32_t(j * n + i), b = a + 1, c = a + uint32_t(n), d = c + 1;
      m->triangles.push_back({a, c, b});
      m->triangles.push_back({b, c, d});
    }
  return m;
}

particles::EmitterDef Def(particles::EmitterShape shape) {
  particles::EmitterDef d;
  d.rate = kCount;
  d.shape = shape;
  d.size = Vec3(4, 1, 4);
  d.velocity = Vec3(0, 5, 0);
  d.spreadDegrees = 20;
  d.lifetime = 3;
  d.lifetimeJitter = 1;
  if (shape == particles::EmitterShape::kMesh) d.mesh = Terrain();
  return d;
}

void BM_EmitMillion(benchmark::State& state) {
  const auto shape = particles::EmitterShape(state.range(0));
  const int calls = int(state.range(1));
  auto made = particles::Emitter::Create(Def(shape));
  if (!made) {
    state.SkipWithError(made.error().message.c_str());
    return;
  }
  const bool reuse = state.range(2) != 0;
  particles::ParticleState s;
  for (auto _ : state) {
    particles::Emitter e = *made;
    if (reuse) {  // emptied, its memory kept (touched): no page faults
      for (auto* v : {&s.mass, &s.invMass, &s.age, &s.lifetime}) v->clear();
      s.position.clear(), s.velocity.clear(), s.color.clear(), s.radius.clear(), s.id.clear();
      s.nextId = 0;
    } else {
      s = particles::ParticleState();
    }
    for (int k = 0; k < calls; ++k) {
      if (!e.Emit(s, 1.0 / calls).ok()) state.SkipWithError("Emit failed");
    }
    benchmark::DoNotOptimize(s.position.data());
    if (s.size() != size_t(kCount)) state.SkipWithError("not a million");
  }
  state.SetItemsProcessed(state.iterations() * kCount);
}
// Shapes: 0 point, 1 sphere, 2 box, 3 disc, 4 mesh; one call or 60 frames;
// into a fresh state (0) or one emptied with its memory kept (1).
BENCHMARK(BM_EmitMillion)
    ->ArgsProduct({{0, 1, 2, 3, 4}, {1}, {0}})
    ->Args({2, 60, 0})
    ->Args({0, 1, 1})
    ->Args({2, 60, 1})
    ->Args({4, 1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// 1M births in 60 frames, each frame's appended to a BulkSystem.
void BM_EmitIntoBulk(benchmark::State& state) {
  auto made = particles::Emitter::Create(Def(particles::EmitterShape::kBox));
  if (!made) {
    state.SkipWithError(made.error().message.c_str());
    return;
  }
  for (auto _ : state) {
    particles::Emitter e = *made;
    particles::ParticleState born;
    particles::BulkSystem bulk;
    for (int k = 0; k < 60; ++k) {
      const size_t first = born.size();
      if (!e.Emit(born, 1.0 / 60).ok()) state.SkipWithError("Emit failed");
      bulk.Append(born, first);
    }
    benchmark::DoNotOptimize(bulk.state.px.data());
  }
  state.SetItemsProcessed(state.iterations() * kCount);
}
BENCHMARK(BM_EmitIntoBulk)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
