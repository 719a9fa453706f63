// How well particle-particle contacts (pairs.cpp) hold a pile: for the
// 10,000 balls of BM_SelfCollidingBalls and the 2,880 of the pile tests
// (PairContacts.APileOf2880Balls...), prints after 1, 2 and 5 s (and every
// 5 s after) the deepest, 99th percentile and mean overlap of touching
// balls (as a fraction of the radius), the pairs whose centres coincide,
// the mean and highest centre, the pairs a ball within 1.01 radius sums,
// the fastest ball, the balls faster than 0.05 m/s and the wall time a
// step; and how far balls moved over the last second.
//   pile_stats [threads [steps [small]]]   (1 thread, 300 steps; `small`:
//                                            the 2,880 balls only)
// The overlaps are measured on the positions, over every pair of centres
// closer than 1.01 (r_i + r_j), found through the neighbour grid.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "ball_scenes.h"
#include "particles/grid.h"
#include "particles/system.h"

namespace {

using namespace sylva;

struct Stats {
  double deepest = 0, p99 = 0, meanOverlap = 0, meanY = 0, maxY = 0, contacts = 0, maxSpeed = 0;
  size_t coincident = 0;  // pairs closer than 1e-9 m
  size_t moving = 0;      // balls faster than 0.05 m/s
};

Stats Measure(const particles::System& sys, double r) {
  const auto& s = sys.state;
  const size_t n = s.size();
  particles::NeighbourGrid grid;
  grid.Build(s.position.data(), n, 2.02 * r);
  Stats st;
  size_t pairs = 0, touching = 0;
  double sumOverlap = 0;
  std::vector<double> overlaps;
  for (size_t i = 0; i < n; ++i) {
    st.meanY += s.position[i].y();
    st.maxY = std::max(st.maxY, s.position[i].y());
    st.maxSpeed = std::max(st.maxSpeed, s.velocity[i].norm());
    st.moving += s.velocity[i].norm() > 0.05;
    grid.ForEachNeighbour(s.position.data(), i, 2.02 * r, [&](size_t j) {
      if (j < i) return;
      ++pairs;
      const double overlap = 2 * r - (s.position[i] - s.position[j]).norm();
      if (overlap > 0) {
        ++touching;
        sumOverlap += overlap;
        overlaps.push_back(overlap / r);
        st.coincident += overlap > 2 * r - 1e-9;
        st.deepest = std::max(st.deepest, overlap / r);
      }
    });
  }
  st.meanY /= double(n);
  if (!overlaps.empty()) {
    auto at = overlaps.begin() + ptrdiff_t(overlaps.size() * 99 / 100);
    std::nth_element(overlaps.begin(), at, overlaps.end());
    st.p99 = *at;
  }
  st.meanOverlap = touching ? sumOverlap / double(touching) / r : 0;
  st.contacts = 2.0 * double(pairs) / double(n);
  return st;
}

int steps_total = 300;
void Run(const char* name, Status (*make)(particles::System&), int threads, double width) {
  particles::System sys(threads);
  if (Status st = make(sys); !st.ok()) {
    std::printf("%s: %s\n", name, st.error().message.c_str());
    std::exit(1);
  }
  // Random close packing (0.64) of the balls over the box's floor.
  const double volume =
      double(sys.state.size()) * 4.0 / 3.0 * 3.14159265358979 * 0.05 * 0.05 * 0.05;
  std::printf(
      "%s, %zu balls, %d thread(s): a pile at 0.64 packing stands %.2f m (mean centre %.2f m)\n",
      name, sys.state.size(), threads, volume / 0.64 / (width * width),
      volume / 0.64 / (width * width) / 2);
  std::printf(
      "   t    deepest  99th pct  mean overlap  coincident  mean y  max y  contacts/ball  "
      "max speed  moving  ms/step\n");
  double ms = 0;
  int steps = 0;
  std::vector<Vec3> before;
  for (int k = 1; k <= steps_total; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    if (Status st = sys.Step(1.0 / 60, particles::Integrator::kSymplecticEuler); !st.ok()) {
      std::printf("step %d: %s\n", k, st.error().message.c_str());
      return;
    }
    ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++steps;
    if (k == steps_total - 60) before = sys.state.position;
    if (k == steps_total) {
      double most = 0;
      size_t over = 0;
      for (size_t i = 0; i < before.size(); ++i) {
        const double d = (sys.state.position[i] - before[i]).norm();
        most = std::max(most, d);
        over += d > 0.01;
      }
      std::printf(
          "   over the last second: the most a ball moved %.4f m; %zu balls moved over 0.01 m\n",
          most, over);
    }
    if (k == 60 || k == 120 || k == 300 || (steps_total > 300 && k % 300 == 0)) {
      const Stats s = Measure(sys, 0.05);
      std::printf(
          "%4.0f s  %6.1f %%  %6.1f %%  %10.2f %%  %10zu  %6.3f  %5.3f  %13.1f  %9.4f  %6zu  "
          "%7.2f\n",
          k / 60.0, 100 * s.deepest, 100 * s.p99, 100 * s.meanOverlap, s.coincident, s.meanY,
          s.maxY, s.contacts, s.maxSpeed, s.moving, ms / steps);
      ms = 0;
      steps = 0;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int threads = argc > 1 ? std::atoi(argv[1]) : 1;
  if (argc > 2) steps_total = std::atoi(argv[2]);
  const bool onlySmall = argc > 3;
  if (!onlySmall) Run("BM_SelfCollidingBalls", bench::AddSelfCollidingBalls, threads, 2.0);
  Run("PairContacts pile", bench::AddPile2880, threads, 1.2);
  return 0;
}
