#include "particles/grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace sylva::particles {
namespace {

TEST(NeighbourGrid, EqualsBruteForceOn10kRandomPoints) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  std::vector<Vec3> x(10000);
  for (auto& p : x) p = Vec3(u(rng), u(rng), u(rng) * 0.2);  // dense in z
  const double r = 0.3;
  for (bool copy : {false, true}) {
    NeighbourGrid grid;
    grid.Build(x.data(), x.size(), r, nullptr, copy);
    size_t total = 0;
    for (size_t i = 0; i < x.size(); i += 7) {
      std::vector<size_t> fromGrid, inSlotOrder, brute;
      grid.ForEachNeighbour(x.data(), i, r, [&](size_t j) { fromGrid.push_back(j); });
      if (copy) {
        grid.ForEachInSlotOrder(x[i], r, [&](size_t k) {
          EXPECT_EQ(grid.sortedPositions()[k], x[grid.order()[k]])
              << "slot-order copy, place " << k;
          if (grid.order()[k] != i) inSlotOrder.push_back(grid.order()[k]);
        });
        // Both queries visit in the same order.
        EXPECT_EQ(inSlotOrder, fromGrid) << "particle " << i;
      }
      for (size_t j = 0; j < x.size(); ++j) {
        if (j != i && (x[j] - x[i]).squaredNorm() <= r * r) brute.push_back(j);
      }
      std::sort(fromGrid.begin(), fromGrid.end());
      ASSERT_EQ(fromGrid, brute) << (copy ? "with" : "without") << " copied positions, particle "
                                 << i << ": grid " << fromGrid.size() << ", brute force "
                                 << brute.size();
      total += brute.size();
    }
    EXPECT_GT(total, 1000u) << "the test should see many neighbours";
  }
}

// The sort is stable and its passes split the work by fixed ranges, so the
// slot order is the same for any thread count, and within a cell the
// particles are in index order; also when most points share a few cells.
// The half neighbourhoods (pairs.cpp's walk) meet every pair closer than
// the cell size exactly once: on a table small enough that cells share
// slots and rows wrap around its end (20 sets of 40 points), and on a larger
// one.
TEST(NeighbourGrid, HalfRangesMeetEachPairOnce) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 21; ++trial) {
    const size_t n = trial < 20 ? 40 : 3000;
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Vec3> x(n);
    for (auto& p : x) p = Vec3(u(rng), u(rng), u(rng));
    x[1] = x[0];  // two particles at one point
    const double r = 0.25;
    NeighbourGrid grid;
    grid.Build(x.data(), n, r, nullptr, true);
    const std::vector<Vec3>& sx = grid.sortedPositions();
    std::vector<std::pair<uint32_t, uint32_t>> half, brute;
    for (uint32_t k = 0; k < n; ++k) {
      grid.ForEachHalfCandidateRange(sx[k], k, [&](uint32_t from, uint32_t to) {
        for (uint32_t j = from; j < to; ++j) {
          if ((sx[j] - sx[k]).squaredNorm() <= r * r)
            half.emplace_back(std::min(k, j), std::max(k, j));
        }
      });
      for (uint32_t j = k + 1; j < n; ++j) {
        if ((sx[j] - sx[k]).squaredNorm() <= r * r) brute.emplace_back(k, j);
      }
    }
    std::sort(half.begin(), half.end());
    const size_t met = half.size();
    half.erase(std::unique(half.begin(), half.end()), half.end());
    EXPECT_EQ(met, half.size()) << n << " points: " << met - half.size() << " pairs met twice";
    EXPECT_EQ(half, brute) << n << " points: " << half.size() << " pairs met, " << brute.size()
                           << " within reach";
  }
}

TEST(NeighbourGrid, SlotOrderIsTheSameForOneAndTwoThreads) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3, 3);
  for (bool clustered : {false, true}) {
    std::vector<Vec3> x(200000);
    for (size_t i = 0; i < x.size(); ++i) {
      x[i] =
          clustered && i % 4 != 0 ? Vec3(0.01 * (i % 3), 0.5, -0.2) : Vec3(u(rng), u(rng), u(rng));
    }
    NeighbourGrid one, two;
    ThreadPool pool(2);
    one.Build(x.data(), x.size(), 0.1, nullptr, true);
    two.Build(x.data(), x.size(), 0.1, &pool, true);
    ASSERT_EQ(one.order(), two.order()) << (clustered ? "clustered" : "uniform");
    ASSERT_EQ(one.sortedPositions(), two.sortedPositions());
    // Index order within a cell: the neighbours of a clustered point come
    // out in increasing index order.
    std::vector<size_t> near;
    two.ForEachNeighbour(x.data(), 1, 0.001, [&](size_t j) { near.push_back(j); });
    EXPECT_TRUE(std::is_sorted(near.begin(), near.end())) << near.size() << " neighbours";
    if (clustered) {
      EXPECT_GT(near.size(), 40000u);
    }
  }
}

TEST(InverseSquare, GridForcesEqualAllPairsWithinTheCutoff) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2, 2);
  ParticleState s;
  for (int i = 0; i < 2000; ++i)
    s.Add(Vec3(u(rng), u(rng), u(rng)), Vec3::Zero(), 0.5 + 0.25 * (u(rng) + 2));
  for (double strength : {1.0, -2.0}) {
    InverseSquare force(strength, 0.5, 0.05);
    std::vector<Vec3> a(s.size(), Vec3::Zero()), b(s.size(), Vec3::Zero());
    force.Accumulate(s, s.position.data(), s.velocity.data(), a.data());
    force.AccumulateAllPairs(s, s.position.data(), b.data());
    double worst = 0, scale = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      worst = std::max(worst, (a[i] - b[i]).norm());
      scale = std::max(scale, b[i].norm());
    }
    EXPECT_LT(worst, 1e-5 * std::max(scale, 1.0))
        << "strength " << strength << ": worst difference " << worst;
  }
}

TEST(InverseSquare, PairForcesConserveMomentum) {
  System sys;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 300; ++i)
    sys.state.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)) * 0.1,
                  1 + 0.5 * u(rng));
  sys.AddForce(std::make_shared<InverseSquare>(-0.01, 0.6, 0.05));
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (size_t i = 0; i < sys.state.size(); ++i) p += sys.state.mass[i] * sys.state.velocity[i];
    return p;
  };
  const Vec3 p0 = momentum();
  for (int i = 0; i < 200; ++i) ASSERT_TRUE(sys.Step(1e-3, Integrator::kRK4).ok());
  EXPECT_LT((momentum() - p0).norm(), 1e-6) << "momentum drifted by " << (momentum() - p0).norm();
}

}  // namespace
}  // namespace sylva::particles
