// The working data of System's particle-particle contacts (pairs.cpp; the
// method is described there), kept between steps so that a step allocates
// nothing once the arrays have grown. Internal to the particle library.
//
// Everything per particle is in the neighbour grid's slot order (particles
// near each other in space are near each other in memory). Each contact is
// stored once, by the particle that found it (its owner; the other is its
// partner), in chunks of kPairChunk owners of that order: one walk of the
// grid finds a chunk's contacts and appends them to the chunk's own array,
// so finding needs no counting pass and no thread writes another's chunk.
// A pass puts each contact's push on its partner in the partner's run of
// PairWork::out, so that each particle reads its pushes in one run.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/math.h"
#include "particles/grid.h"

namespace sylva::particles {

// Particles a chunk of contacts: the unit of parallel work.
constexpr size_t kPairChunk = 256;

// What the passes read of a contact between its owner p and partner q
// (both in slot order), apart from q. 40 bytes. (A normal rounded to single
// precision lost 9e-10 of an elastic gas's energy in 200 steps, against
// 1e-12 asked, and left a pile unsettled.)
struct PairContact {
  Vec3 n;         // unit, from q toward p, at the time of impact
  double target;  // relative normal speed the velocity passes aim for
  double k;       // the pair's sharing factor over its inverse mass sum
};

// A chunk's contacts, owner by owner, as parallel arrays (the passes read
// contacts, q and impulse; finding writes first and bounce for the
// partners' sake).
struct PairChunk {
  std::vector<PairContact> contacts;
  std::vector<uint32_t> q;      // the partner's place in slot order
  std::vector<double> impulse;  // summed over the velocity passes, in units of k
  std::vector<double> first;    // time of impact in the step
  std::vector<uint8_t> bounce;  // faster than the step's forces: leaves at e times vn0
  uint32_t base = 0;            // its first contact's place among all (PairWork::out)
  double speed = 0;             // the fastest approach |vn0| among them
  double residual = 0;          // the largest bounce residual of the last pass
  bool resting = false;         // one of them is resting contact
};

struct PairWork {
  NeighbourGrid grid;
  std::vector<Vec3> x0, v0;  // particle order: the state at the start of the step
  // Per particle, slot order: position (end of the step, then the position
  // passes'), displacement over the step, velocity, what the step's forces
  // changed the velocity by, scratch, a pass's sum over the particle's own
  // contacts.
  std::vector<Vec3> x, d, v, dv, scratch, own;
  std::vector<Vec3> xv;  // position after the velocity passes

  std::vector<double> w, r, move, first;  // inverse mass, radius, |d|, first contact time
  std::vector<uint32_t> begin, end;       // p's own contacts: [begin, end) of its chunk's
  std::vector<uint32_t> count;            // contacts of p, its own and as partner
  // A pass's push of each contact on its partner, in the contacts' order
  // (a chunk's from its base: each thread writes its own range); p's as a
  // partner are out[pushFrom[j]] for j in [partnerBegin[p], partnerBegin[p
  // + 1]), in the order of their owners' chunks and lists. (Written to the
  // partner's run instead, the two threads' random writes shared cache
  // lines: the velocity passes took as long on two threads as on one.)
  std::vector<uint32_t> partnerBegin, pushFrom;
  std::vector<size_t> partBegin;  // the passes' parts of the chunks, a thread each
  std::vector<Vec3> out;
  // The support sweep (System::SupportSweep): the particles by height,
  // (height, slot); for the k-th in that order, the places in it of the
  // particles before it near enough to touch, near[nearBegin[k],
  // nearBegin[k + 1]), found as (higher, lower) pairs a chunk of the
  // sweep's grid at a time (nearChunks); nearEnd: the lists' counts and
  // cursors as they are filled; what the sweep moved each by (slot order).
  std::vector<std::pair<double, uint32_t>> byHeight, byHeightScratch;
  std::vector<uint32_t> near, nearBegin, nearEnd;
  // The pipelined sweeps: the last turn that touches each place, and the
  // last one the k-th turn of a sweep waits for in the sweep before.
  std::vector<uint32_t> sweepReach, sweepWait;
  std::vector<std::vector<uint32_t>> nearChunks;
  // The sweep's pairs are gathered from a grid of their own, over the
  // positions in order of height, its cells as small as their reach (the
  // contacts' grid, over the start positions, has cells as large as the
  // step's fastest move: five times the candidates in a falling pile).
  NeighbourGrid sweepGrid;
  std::vector<Vec3> swept, xh;  // xh, wh, rh: x, w, r in order of height
  std::vector<double> wh, rh;
  std::vector<uint8_t> free, resting;  // v == v0 (free flight); has a resting contact
  std::vector<PairChunk> chunks;
  // The last step's velocity passes: how many ran, and for a step with no
  // resting contact whether every collision met its target within the
  // tolerance (a step that reached the limit first is reported).
  int passes = 0;
  bool gas = false, converged = true;
  double residual = 0, tolerance = 0;
};

}  // namespace sylva::particles
