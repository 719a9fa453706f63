// Triangulating a turtle polygon `{ ... }`: ear clipping of a simple polygon
// (any orientation, concave allowed) in its best-fit plane.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"

namespace sylva::mesh {

// Triangles as index triples into `vertices` (n - 2 of them for a simple
// polygon of n distinct vertices); empty when the polygon is degenerate
// (fewer than 3 distinct vertices, zero area) or so self-intersecting that
// no ear remains. *normalOut gets the unit Newell normal.
//
// Time: each ear test looks only at the live reflex vertices in the grid
// cells the ear crosses. Measured work grows as about n^1.5 on spirals and
// random stars, and linearly on combs (130,000-vertex spiral: tens of ms;
// the old clipper took over two minutes). Work is bounded by n (64 + sqrt n)
// steps, after which the polygon counts as degenerate (no triangles).
std::vector<uint32_t> TriangulatePolygon(const std::vector<Vec3>& vertices, Vec3* normalOut);

}  // namespace sylva::mesh
