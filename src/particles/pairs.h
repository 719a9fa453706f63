// The working data of System's particle-particle contacts (pairs.cpp; the
// method is described there), kept between steps so that a step allocates
// nothing once the arrays have grown. Internal to the particle library.
//
// Everything per particle is in the neighbour grid's slot order (particles
// near each other in space are near each other in memory), and the
// contacts are kept in chunks of kPairChunk particles of that order: one
// walk of the grid finds a chunk's contacts and appends them to the
// chunk's own array, so finding needs no counting pass and no thread
// writes another's chunk.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "particles/grid.h"

namespace sylva::particles {

// Particles a chunk of contacts: the unit of parallel work.
constexpr size_t kPairChunk = 256;

// Particle p's side of a contact with particle j (both in slot order); j
// holds the mirror image (the opposite normal, the same numbers), so each
// particle gathers its impulses alone. 56 bytes.
struct PairContact {
  Vec3 n;          // unit, from j toward p, at the time of impact
  double impulse;  // summed over the velocity passes, in units of k
  double target;   // relative normal speed the velocity passes aim for
  double k;        // the pair's sharing factor over its inverse mass sum
  uint32_t j;      // the other particle's place in slot order
  bool bounce;     // faster than the step's forces: leaves at e times vn0
};

struct PairChunk {
  std::vector<PairContact> contacts;  // its particles' contacts, particle by particle
  double speed = 0;                   // the fastest approach |vn0| among them
  double residual = 0;                // the largest bounce residual of the last pass
  bool resting = false;               // one of them is resting contact
};

struct PairWork {
  NeighbourGrid grid;
  std::vector<Vec3> x0, v0;  // particle order: the state at the start of the step
  // Per particle, slot order: position (end of the step, then the position
  // passes'), displacement over the step, velocity, what the step's forces
  // changed the velocity by, scratch.
  std::vector<Vec3> x, d, v, dv, scratch;
  std::vector<double> w, r, move, first;  // inverse mass, radius, |d|, first contact time
  std::vector<uint32_t> begin, end;       // p's contacts: [begin, end) of its chunk's
  std::vector<uint8_t> free, resting;     // v == v0 (free flight); has a resting contact
  std::vector<PairChunk> chunks;
  // The last step's velocity passes: how many ran, and for a step with no
  // resting contact whether every collision met its target within the
  // tolerance (a step that reached the limit first is reported).
  int passes = 0;
  bool gas = false, converged = true;
  double residual = 0, tolerance = 0;
};

}  // namespace sylva::particles
