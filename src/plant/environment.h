// Environment: what answers the ?E queries of an open L-system
// (Mech & Prusinkiewicz, "Visual models of plants interacting with their
// environment", SIGGRAPH 1996).
//
// After each derivation step (and once on the axiom) the plant library
// draws the word (interpretation rules first), collects every ?E module with
// the turtle's position and frame there, and hands them all to Answer() in
// one call. The environment writes its answer into each query's parameters;
// the next step's productions read them. Several plants may share one
// environment (a light grid they compete in): the caller then passes the
// queries of all of them in one call, each tagged with its plant.
//
// Built-in environments (docs/grammar.md, "Environment", chooses one with
// `environment:`):
//   shape  (plant/shape_environment.h): 1 inside a box, sphere or
//          ellipsoid, 0 outside: topiary pruning.
//   light  (plant/light_grid.h): the light a bud receives in a voxel
//          shadow-propagation grid (Palubicki et al. 2009), 0..1.
//   terrain (plant/ground_environment.h): the ground's height and normal
//          under the query (a scene's terrain, or the plane y = 0).
// Without `environment:`, a grammar in a cpfg object folder is answered by
// the environment program its .e file names (plant/cpfg_environment.h:
// honda81, ecosystem, clover, chiba built in).
// GL-free; units are the grammar's.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "core/math.h"
#include "core/status.h"
#include "lsys/grammar.h"
#include "mesh/plant_geometry.h"

namespace sylva::plant {

// One ?E module to answer.
struct EnvQuery {
  Vec3 position{0, 0, 0};    // the turtle's position at the module
  mesh::Frame frame;         // its heading, left and up there
  std::span<double> params;  // in: the module's parameters; out: the answer
  uint32_t plant = 0;        // which plant asked (0 for a plant alone)
};

class Environment {
 public:
  virtual ~Environment() = default;
  // Answers every query of one step. An error (the environment cannot hold
  // the plant: a light grid past its cell limit) ends the growth.
  virtual Status Answer(std::span<EnvQuery> queries) = 0;
};

struct Ground;

// The environment a grammar's `environment:` statement names, or an error
// at the statement (an unknown kind, key or shape, a bad value), with the
// line quoted from `g`. `ground` is what `environment: terrain` answers
// from (null: the plane y = 0).
Expected<std::unique_ptr<Environment>> MakeEnvironment(const lsys::EnvironmentStatement& statement,
                                                       const lsys::Grammar& g,
                                                       const Ground* ground = nullptr);

}  // namespace sylva::plant
