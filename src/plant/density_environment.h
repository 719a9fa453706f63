// Two of cpfg's environment programs, built in: the collision ("density")
// programs of vlab's open L-systems (Mech & Prusinkiewicz, "Visual models of
// plants interacting with their environment", SIGGRAPH 1996, section 5;
// H. Honda, P. B. Tomlinson & J. B. Fisher, Am. J. Botany 68, 1981).
// cpfg runs them as separate processes (docs/cpfg.md, "Environment
// programs"); Sylva answers the same ?E modules with the same rules.
//
// honda81, ?E(vigor[, group]): after each step every ?E is a point. A point
// reads 0 when another point of the same group (the whole part of the second
// parameter, 0 when there is none) with a vigor at least as high lies within
// `radius` of it, else 1. Two points of equal vigor closer than the radius
// both read 0. Spec file (`density.spec`): `radius: R` (default 0: only
// points in the same place collide), `3d case: on` (default off: the
// distance is measured in x and z, the horizontal plane of cpfg's turtle,
// which starts heading up +y), `verbose:`.
//
// ecosystem (and ecosystemR), ?E(r[, group]) or, with `vigor: on`,
// ?E(r, vigor): every ?E is a disc (a sphere in 3D) of radius r. Without
// vigor a disc reads 0 when it overlaps (centre distance <= sum of radii)
// another of its group at least as large, else 1: small plants shaded by
// larger ones die (self-thinning). With `vigor: on` there are no groups;
// the discs are visited in the order of the word, and one reads 0 when it
// overlaps a disc not yet removed that has a higher vigor (or the same
// vigor and a larger radius), and is then removed itself. Spec file:
// `3d case: on|yes`, `vigor: on`, `grid size:` (cpfg's acceleration grid,
// which does not change the answers), `verbose:`.
//
// Both read positions as single-precision floats, as the programs do, so a
// point exactly at the radius collides as it does in cpfg. The pairs are
// found through a uniform grid of cells one reach wide (plant/point_grid.h;
// the programs use a grid too): O(n log n + pairs in neighbouring cells).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/math.h"

namespace sylva::plant {

struct Honda81Def {
  double radius = 0;  // `radius:`
  bool is3d = false;  // `3d case: on`
};

struct EcosystemDef {
  bool is3d = false;   // `3d case: on` or `yes`
  bool vigor = false;  // `vigor: on`
};

// One query as the programs see it: the turtle position and the ?E
// parameters (at least one).
struct DensityQuery {
  Vec3 position{0, 0, 0};
  std::span<const double> params;
};

// The answer of each query, in order: 1 (free) or 0 (collides).
std::vector<double> Honda81Answers(const Honda81Def& def, std::span<const DensityQuery> queries);
std::vector<double> EcosystemAnswers(const EcosystemDef& def,
                                     std::span<const DensityQuery> queries);

}  // namespace sylva::plant
