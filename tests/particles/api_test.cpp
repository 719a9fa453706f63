// The API for building effects (issue 17): force handles, forces that
// outlive their system, explicit pinning instead of mass 0, springs that
// follow their particles through RemoveDead, and BulkSystem::Append's
// growth.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "helpers.h"
#include "particles/bulk.h"
#include "particles/emitter.h"
#include "particles/forces.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

bool Contains(const Status& s, const std::string& text) {
  return !s.ok() && s.error().message.find(text) != std::string::npos;
}

TEST(Forces, RemovedByHandleTheyStopActing) {
  System s;
  s.state.Add(Vec3::Zero(), Vec3::Zero());
  const ForceHandle g = s.AddForce(std::make_shared<Gravity>(Vec3(0, -10, 0)));
  STEP_OK(s, 0.1, Integrator::kSymplecticEuler);
  EXPECT_DOUBLE_EQ(s.state.velocity[0].y(), -1.0) << "gravity acted for one step";
  ASSERT_OK(s.RemoveForce(g));
  EXPECT_EQ(s.forceCount(), 0u);
  for (int i = 0; i < 5; ++i) STEP_OK(s, 0.1, Integrator::kSymplecticEuler);
  EXPECT_DOUBLE_EQ(s.state.velocity[0].y(), -1.0) << "the removed gravity still acts";
}

TEST(Forces, StaleForeignAndDefaultHandlesAreErrors) {
  System s, other;
  const ForceHandle g = s.AddForce(std::make_shared<Gravity>(Vec3(0, -10, 0)));
  const ForceHandle d = s.AddForce(std::make_shared<Drag>(0.5));
  const ForceHandle foreign = other.AddForce(std::make_shared<Drag>(0.5));
  ASSERT_OK(s.RemoveForce(g));
  const Status again = s.RemoveForce(g);
  EXPECT_TRUE(Contains(again, "names no force of this system"))
      << (again.ok() ? "removed twice without error" : again.error().message);
  EXPECT_TRUE(Contains(s.ReplaceForce(g, std::make_shared<Drag>(1)), "names no force"))
      << "replaced through a removed handle";
  EXPECT_TRUE(Contains(s.RemoveForce(foreign), "names no force")) << "another system's handle";
  EXPECT_TRUE(Contains(s.RemoveForce(ForceHandle{}), "default handle"));
  EXPECT_EQ(s.force(g), nullptr);
  EXPECT_EQ(s.force(foreign), nullptr);
  EXPECT_NE(s.force(d), nullptr);
  EXPECT_EQ(s.forceCount(), 1u) << "a refused handle changed the forces";
  EXPECT_EQ(other.forceCount(), 1u) << "another system's force was removed";
}

TEST(Forces, ReplacedAndChangedBetweenSteps) {
  System s;
  s.state.Add(Vec3::Zero(), Vec3::Zero(), 2);
  auto gravity = std::make_shared<Gravity>(Vec3(0, -10, 0));
  const ForceHandle g = s.AddForce(gravity);
  // Changed through the caller's pointer: g = -4 for one step.
  gravity->set_g(Vec3(0, -4, 0));
  STEP_OK(s, 0.5, Integrator::kSymplecticEuler);
  EXPECT_DOUBLE_EQ(s.state.velocity[0].y(), -2.0) << "set_g: v = g h";
  // Replaced: a drag in its place.
  ASSERT_OK(s.ReplaceForce(g, std::make_shared<Drag>(2.0)));
  EXPECT_EQ(s.force(g)->local(), true);
  STEP_OK(s, 0.5, Integrator::kSymplecticEuler);
  // v1 = v0 + h (-k v0) / m = -2 + 0.5 * (2 * 2) / 2 = -1.
  EXPECT_DOUBLE_EQ(s.state.velocity[0].y(), -1.0) << "the replacing drag";
  // A changed parameter out of range: the next step says so (NaN in z).
  ASSERT_OK(s.ReplaceForce(g, gravity));
  gravity->set_g(Vec3(0, -10, std::nan("")));
  const Status st = s.Step(0.5, Integrator::kSymplecticEuler);
  EXPECT_TRUE(Contains(st, "Gravity g")) << (st.ok() ? "NaN in g stepped" : st.error().message);
}

// A force shared with the caller keeps working after its system (and the
// system's thread pool) is gone: it runs serially, never on a freed pool.
// Before handles, the force kept the destroyed pool (a use-after-free).
TEST(Forces, ASharedForceOutlivesItsSystem) {
  constexpr int kN = 20000;
  auto springs = std::make_shared<Springs>();
  for (int i = 0; i + 1 < kN; ++i)
    ASSERT_OK(springs->Add(uint32_t(i), uint32_t(i + 1), 0.5, 100, 1));
  ParticleState kept;
  {
    System s(4);
    for (int i = 0; i < kN; ++i) s.state.Add(Vec3(0.6 * i, 0.01 * (i % 7), 0), Vec3::Zero());
    s.AddForce(springs);
    STEP_OK(s, 1e-3, Integrator::kSymplecticEuler);
    EXPECT_NE(springs->pool(), nullptr) << "a 4-thread system lends its pool";
    kept = s.state;
  }
  EXPECT_EQ(springs->pool(), nullptr) << "the destroyed system's pool is still held";
  std::vector<Vec3> f(kN, Vec3::Zero());
  springs->Accumulate(kept, kept.position.data(), kept.velocity.data(), f.data());
  Vec3 sum = Vec3::Zero();
  double largest = 0;
  for (const Vec3& fi : f) sum += fi, largest = std::max(largest, fi.norm());
  EXPECT_GT(largest, 1.0) << "the springs pulled nothing";
  EXPECT_LT(sum.norm(), 1e-9 * largest * kN) << "forces do not cancel: " << sum.transpose();
}

// One force shared by two live systems that step in turn, one of them
// changing its threads and the other destroyed while the force holds its
// pool: each system's steps equal those of a system with a force of its
// own (the same bits), and the force never keeps a pool that is gone.
TEST(Forces, ASharedForceServesTwoSystemsThroughAThreadChange) {
  constexpr int kN = 20000;
  auto chain = [] {
    auto springs = std::make_shared<Springs>();
    for (int i = 0; i + 1 < kN; ++i)
      EXPECT_OK(springs->Add(uint32_t(i), uint32_t(i + 1), 0.5, 100, 1));
    return springs;
  };
  auto fill = [](System& s, double y) {
    for (int i = 0; i < kN; ++i) s.state.Add(Vec3(0.6 * i, y + 0.01 * (i % 7), 0), Vec3::Zero());
  };
  const auto shared = chain();
  System a(4), ownA(1), ownB(1);
  fill(a, 0), fill(ownA, 0), fill(ownB, 1);
  a.AddForce(shared);
  ownA.AddForce(chain());
  ownB.AddForce(chain());
  {
    System b(2);
    fill(b, 1);
    b.AddForce(shared);
    for (int k = 0; k < 3; ++k) {
      STEP_OK(a, 1e-3, Integrator::kSymplecticEuler);
      STEP_OK(ownA, 1e-3, Integrator::kSymplecticEuler);
      if (k == 1) a.SetThreads(3);
      STEP_OK(b, 1e-3, Integrator::kImplicitEuler);
      STEP_OK(ownB, 1e-3, Integrator::kImplicitEuler);
    }
    EXPECT_NE(shared->pool(), nullptr) << "b's pool was not lent for its step";
    EXPECT_EQ(b.state.position, ownB.state.position) << "b's steps differ from its own force's";
  }
  EXPECT_EQ(shared->pool(), nullptr) << "the destroyed b's pool is still held by the force";
  STEP_OK(a, 1e-3, Integrator::kSymplecticEuler);
  STEP_OK(ownA, 1e-3, Integrator::kSymplecticEuler);
  EXPECT_EQ(a.state.position, ownA.state.position) << "a's steps differ from its own force's";
}

TEST(State, ZeroMassIsAnErrorNotAPin) {
  for (double bad : {0.0, -1.0, std::nan(""), 1e31}) {
    System s;
    s.state.Add(Vec3(0, 1, 0), Vec3(1, 0, 0));
    s.state.Add(Vec3(0, 2, 0), Vec3(1, 0, 0), bad);
    s.AddForce(std::make_shared<Gravity>(Vec3(0, -10, 0)));
    const Status st = s.Step(0.1, Integrator::kSymplecticEuler);
    EXPECT_TRUE(Contains(st, "particle id 1 has mass"))
        << "mass " << bad << ": " << (st.ok() ? "stepped" : st.error().message);
    EXPECT_EQ(s.state.position[0], Vec3(0, 1, 0)) << "mass " << bad << ": something moved";
    // Pinned explicitly, it stays put; the others move.
    s.state.Pin(1);
    STEP_OK(s, 0.1, Integrator::kSymplecticEuler);
    EXPECT_EQ(s.state.position[1], Vec3(0, 2, 0)) << "mass " << bad << ": the pinned one moved";
    EXPECT_NE(s.state.position[0], Vec3(0, 1, 0)) << "mass " << bad << ": the free one is still";
  }
  // The same in BulkSystem.
  BulkSystem b;
  b.state.Add(Vec3(0, 1, 0), Vec3::Zero(), 0);
  b.fields.gravity = Vec3(0, -10, 0);
  const Status st = b.Step(0.1);
  EXPECT_TRUE(Contains(st, "particle id 0 has mass 0 kg"))
      << (st.ok() ? "stepped" : st.error().message);
  b.state.Pin(0);
  ASSERT_OK(b.Step(0.1));
  EXPECT_EQ(b.state.position(0), Vec3(0, 1, 0)) << "the pinned bulk particle moved";
}

TEST(State, PinnedParticlesKeepTheirMass) {
  System s;
  s.state.AddPinned(Vec3(1, 2, 3), 4);
  s.state.Add(Vec3::Zero(), Vec3(2, 0, 0), 3);
  EXPECT_TRUE(s.state.pinned(0));
  EXPECT_EQ(s.state.mass[0], 4);
  EXPECT_DOUBLE_EQ(s.KineticEnergy(), 6.0) << "3 kg at 2 m/s; the pinned one counts nothing";
  s.state.Unpin(0);
  EXPECT_DOUBLE_EQ(s.state.invMass[0], 0.25);
}

// Springs join particles, not indices: RemoveDead in the library renumbers
// them, and drops the springs of the dead.
TEST(Springs, FollowTheirParticlesThroughRemoveDead) {
  System s;
  for (int i = 0; i < 5; ++i) s.state.Add(Vec3(i, 0, 0), Vec3::Zero(), 1, i == 1 ? 0.05 : 1e9);
  auto springs = std::make_shared<Springs>();
  for (uint32_t i = 0; i + 1 < 5; ++i) ASSERT_OK(springs->Add(i, i + 1, 0.5, 10, 0));
  auto penalty = std::make_shared<Penalty>();
  penalty->Anchor(1, Vec3(1, 1, 0), 7, 0);  // goes with id 1
  penalty->Distance(1, 3, 0.5, 3, 0);       // goes with id 1
  penalty->Anchor(4, Vec3(4, 1, 0), 5, 0);
  s.AddForce(springs);
  s.AddForce(penalty);
  STEP_OK(s, 0.1, Integrator::kSymplecticEuler);  // particle id 1 dies (age 0.1)
  EXPECT_EQ(s.RemoveDead(), 1u);
  ASSERT_EQ(s.state.size(), 4u);
  EXPECT_EQ(s.state.id[1], 2u) << "ids keep their order";
  ASSERT_EQ(springs->springs().size(), 2u) << "the two springs of id 1 go";
  // Spring 2-3 and 3-4 by id are now between indices 1-2 and 2-3.
  EXPECT_EQ(springs->springs()[0].a, 1u);
  EXPECT_EQ(springs->springs()[0].b, 2u);
  EXPECT_EQ(springs->springs()[1].a, 2u);
  EXPECT_EQ(springs->springs()[1].b, 3u);
  // The forces equal those of a system built afresh from the survivors.
  System fresh;
  fresh.state = s.state;
  auto s2 = std::make_shared<Springs>();
  ASSERT_OK(s2->Add(1, 2, 0.5, 10, 0));
  ASSERT_OK(s2->Add(2, 3, 0.5, 10, 0));
  auto p2 = std::make_shared<Penalty>();
  p2->Anchor(3, Vec3(4, 1, 0), 5, 0);
  fresh.AddForce(s2);
  fresh.AddForce(p2);
  std::vector<Vec3> a(4), b(4);
  s.Accelerations(s.state.position.data(), s.state.velocity.data(), a.data());
  fresh.Accelerations(fresh.state.position.data(), fresh.state.velocity.data(), b.data());
  for (size_t i = 0; i < 4; ++i)
    EXPECT_EQ(a[i], b[i]) << "particle " << i << ": " << a[i].transpose() << " against "
                          << b[i].transpose();
  EXPECT_EQ(penalty->Energy(s.state.position.data()), p2->Energy(s.state.position.data()))
      << "the penalty terms of id 1 go, the anchor of id 4 follows it to index 3";
  STEP_OK(s, 0.1, Integrator::kImplicitEuler);
}

// Appending a few particles at a time grows the arrays geometrically: few
// reallocations (an exact reserve on every call made one a call).
TEST(Bulk, AppendGrowsGeometrically) {
  ParticleState born;
  BulkSystem b;
  int reallocations = 0;
  const float* data = nullptr;
  for (int k = 0; k < 10000; ++k) {
    const size_t first = born.size();
    born.Add(Vec3(k, 0, 0), Vec3::Zero());
    b.Append(born, first);
    if (b.state.px.data() != data) ++reallocations, data = b.state.px.data();
  }
  ASSERT_EQ(b.state.size(), 10000u);
  EXPECT_LE(reallocations, 20) << "reallocations over 10,000 appends of one particle";
  EXPECT_EQ(b.state.id.back(), 9999u);
}

}  // namespace
}  // namespace sylva::particles
