// Hard constraints: colliders a particle cannot pass (Angel & Shreiner 9.6;
// Baraff & Witkin, "Physically Based Modeling", collision and contact).
//
// Every collider answers one question: where does the straight path a -> b
// (a particle's motion over one step) first enter the solid? The answer is
// exact for that path: a fraction s of the step found in closed form (plane,
// sphere, box slabs, polygon and triangle crossings), the point on the
// surface and its outward unit normal. The system then turns the contact
// into a response (see RespondToContacts below): bounce with restitution and Coulomb
// friction, resting or sliding contact, stick, or kill.
//
// Kinds:
//   plane    half-space; the particle stays on the side the normal points to
//   sphere   outside (a ball to bounce off) or inside (a bowl that holds)
//   box      axis-aligned; outside (an obstacle) or inside (a container)
//   polygon  convex and planar, two-sided (a thin panel)
//   mesh     triangles with a bounding-volume hierarchy, two-sided
//   capsules segments with a radius (a plant's branches), with a bounding-
//            volume hierarchy (capsules.h); solid, entered from outside
//
// Thin two-sided surfaces (polygon, mesh) leave a contact point a small skin
// (1e-9 relative) on the particle's side, so rounding can never put it on
// the far side where the next step would not see a crossing.
//
// RespondToContacts turns contacts into the response, for both particle
// systems (System, double precision, and BulkSystem, single).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.h"
#include "core/status.h"

namespace sylva::particles {

class CapsuleBvh;
class TriangleBvh;

// What one particle remembers of the mesh it lies on, between its queries
// (a particle system keeps one a particle; 112 bytes): every triangle but
// near[0..count) is at least `clear` from `centre` (the hierarchy's
// coordinates). A query whose path (of a ball of radius r) stays within
// clear - r (less a rounding margin) of the centre can touch only those,
// so it tests only them, taking the first in the order the full query
// meets them: the same answer, bit for bit. Any content is safe (a memo is
// checked before use); a full query that finds a contact refreshes it.
struct MeshMemo {
  static constexpr int kNear = 8;
  uint64_t mesh = 0;  // TriangleBvh::serial() of its mesh; 0: nothing remembered
  Vec3 centre{0, 0, 0};
  double clear = 0;
  uint32_t near[kNear] = {};
  float dist[kNear] = {};  // each one's distance from the centre, rounded down
  int count = 0;
};

// What happens to a particle that hits a collider.
enum class Response {
  kBounce,  // restitution and Coulomb friction; resting contact when slow
  kStick,   // stays at the contact point, immovable from then on
  kKill,    // dies at the contact point (lifetime set to its age)
};

struct Contact {
  double s = 0;  // fraction of the path a -> b, in [0, 1]
  Vec3 point;    // on the surface (plus the skin for thin surfaces)
  Vec3 normal;   // unit, pointing to the side the particle came from
};

// Triangles with an axis-aligned bounding-volume hierarchy (median split on
// the longest axis of the centroids' box, at most 4 triangles a leaf) for
// long paths, and a uniform grid for short ones (a particle's step); both
// give the same first crossing.
class TriangleBvh {
 public:
  TriangleBvh(std::vector<Vec3> vertices, std::vector<std::array<uint32_t, 3>> triangles);
  // First crossing of the segment a -> b with any triangle, either side.
  // With r > 0, the first entry into the triangles grown by r (the set of
  // points within r of a triangle: two faces offset by r, and a capsule of
  // radius r about every edge): where a ball of radius r centred on the
  // path first touches a triangle. The contact point is the ball's centre.
  // With a memo (see MeshMemo), a short path near the memo's centre tests
  // only the triangles it lists, and a full query that finds a contact
  // refreshes it: the same answer either way.
  bool Intersect(const Vec3& a, const Vec3& b, Contact* c, double r = 0,
                 MeshMemo* memo = nullptr) const;
  // A number no other hierarchy of this process has (MeshMemo::mesh).
  uint64_t serial() const { return serial_; }
  // The bounding box of every triangle.
  Vec3 lo() const { return nodes_.empty() ? Vec3::Zero() : nodes_[0].lo; }
  Vec3 hi() const { return nodes_.empty() ? Vec3::Zero() : nodes_[0].hi; }
  // Whether the box of the segment a -> b grown by r overlaps the box of a
  // leaf of the hierarchy (a few triangles): false means no triangle is
  // within r of the path. The broad phase of a mesh collider.
  // A memo (MeshMemo) answers for a path within its ball.
  bool Near(const Vec3& a, const Vec3& b, double r, const MeshMemo* memo = nullptr) const;
  // Near's first and cheapest screen, which reads no memo: true where the
  // box of the path grown by r is clear of the hierarchy's box, or of the
  // triangles of the few grid columns it covers (see columns_); then Near
  // is false. A caller may run it over many particles first and fetch the
  // memos of the rest ahead of Near.
  bool Clear(const Vec3& a, const Vec3& b, double r) const {
    if (nodes_.empty()) return true;
    const Vec3 lo = a.cwiseMin(b) - Vec3::Constant(r), hi = a.cwiseMax(b) + Vec3::Constant(r);
    // Clear of every triangle's box (a flake high above a terrain).
    if ((lo.array() > nodes_[0].hi.array()).any() || (hi.array() < nodes_[0].lo.array()).any())
      return true;
    return ClearOfColumns(lo, hi);
  }
  size_t triangleCount() const { return tris_.size(); }
  size_t nodeCount() const { return nodes_.size(); }
  int depth() const { return depth_; }

 private:
  struct Node {
    Vec3 lo, hi;
    uint32_t first = 0, count = 0;  // leaf: triangles [first, first + count); inner: count = 0
    uint32_t left = 0, right = 0;
  };
  uint32_t Build(uint32_t first, uint32_t count, int depth);
  void BuildGrid();
  bool HitTriangle(uint32_t i, const Vec3& a, const Vec3& b, double r, double best,
                   Contact* c) const;
  // The query through the memo's triangles alone, over the grid cells [l, h].
  // For a path within the memo's ball: how far from the centre (plus r and
  // a rounding margin) a triangle may be and still be touched; else -1.
  double MemoReach(const MeshMemo* memo, const Vec3& a, const Vec3& b, double r) const;
  // The query through the memo's triangles within `reach` of its centre
  // alone, over the grid cells [l, h].
  bool IntersectNear(const MeshMemo& memo, double reach, const Vec3& a, const Vec3& b, Contact* c,
                     double r, const int l[3], const int h[3]) const;
  // Lists in `memo` the triangles near `centre` for a ball of radius r.
  void Remember(const Vec3& centre, double r, MeshMemo* memo) const;
  // What a triangle test reads, in one place (176 bytes): the corners,
  // the normal n = (v1 - v0) x (v2 - v0) and nn = |n|^2, n / sqrt(nn) (the
  // bits the test computed from the corners before), and the box.
  struct Face {
    Vec3 v[3];
    Vec3 n;
    double nn;
    Vec3 unit;
    Vec3 lo, hi;
  };
  uint64_t serial_ = 0;
  std::vector<Vec3> v_;
  std::vector<std::array<uint32_t, 3>> tris_;
  std::vector<Face> faces_;  // by triangle, in tris_'s order
  std::vector<Node> nodes_;
  int depth_ = 0;
  // A uniform grid (about eight cells a triangle, at most 256 an axis) for
  // short paths, the common query: cell (x, y, z) lists the triangles whose
  // boxes touch it, items_[start_[cell] .. start_[cell + 1]). 4 bytes a cell
  // and a listing.
  Vec3 gridLo_ = Vec3::Zero();
  double cell_ = 1;
  int dims_[3] = {0, 0, 0};
  std::vector<uint32_t> start_, items_;
  // The cells each triangle is listed in: lo x, y, z, hi x, y, z.
  std::vector<std::array<uint8_t, 6>> cells_;
  // The grid's columns along its thinnest axis up_ (a terrain's height):
  // column (cu, cw) over the cells of the other two axes u, w (index
  // cu + dims_[u] cw) bounds, along up_, the boxes of the triangles listed
  // in its cells (floats rounded outward; an empty column has lo > hi).
  // Near's cheapest screen: a path whose box, grown by r, lies above or
  // below the bound in every column it covers touches no triangle (a flake
  // high over a terrain). 8 bytes a column.
  struct Column {
    float lo, hi;
  };
  int up_ = 1;
  std::vector<Column> columns_;
  // Whether the box lo..hi is clear of the triangles of the few columns
  // it covers (false where it covers more than four).
  bool ClearOfColumns(const Vec3& lo, const Vec3& hi) const;
  // The cell of coordinate x along axis k, clamped to the grid (x not NaN).
  int CellOf(double x, int k) const {
    return int(std::clamp(std::floor((x - gridLo_[k]) / cell_), 0.0, double(dims_[k] - 1)));
  }
};

// A collider is a plain description; the factories below fill it, and
// System::AddCollider / BulkSystem::AddCollider run Validate on it, so a bad
// number (a zero or NaN normal, a negative radius) is a Diagnostic there,
// never a collider that silently does nothing. Ranges (m unless said):
struct Collider {
  enum class Kind { kPlane, kSphere, kBox, kPolygon, kMesh, kCapsules };
  Kind kind = Kind::kPlane;
  // plane / polygon: point and unit normal; sphere: centre = point, radius;
  // box: lo, hi. Every coordinate within +-1e12.
  Vec3 point{0, 0, 0}, normal{0, 1, 0};     // normal: unit length (within 1e-6)
  double radius = 1;                        // 1e-12..1e12
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};            // lo <= hi in every axis
  bool inside = false;                      // sphere and box: keep particles inside
  std::vector<Vec3> polygon;                // convex, counter-clockwise about normal, >= 3 vertices
  std::shared_ptr<const TriangleBvh> mesh;  // not null for kMesh
  std::shared_ptr<const CapsuleBvh> capsules;  // not null for kCapsules
  // Kinematic motion: the solid translates at this velocity (m/s, each
  // component within +-1e12), and a contact responds to the particle's
  // velocity relative to it (a moving plane or ball pushes and carries
  // particles). System::Step and BulkSystem::Step move it by h times its
  // velocity after each step (Translate). Every kind; a mesh or capsules
  // keep their shared hierarchy and move by `offset`.
  Vec3 velocity{0, 0, 0};
  // Mesh and capsules: where the triangles or capsules are, relative to
  // their hierarchy's coordinates (Translate adds to it; queries subtract
  // it from the path and add it to the contact point). 0 unless moved.
  Vec3 offset{0, 0, 0};
  // Material.
  double restitution = 1;  // e: normal speed out / in, 0..1
  double friction = 0;     // Coulomb mu, 0..1e3: tangential impulse <= mu * normal impulse
  Response response = Response::kBounce;

  // Plane's normal need not be unit (it is normalised); a zero or NaN
  // normal stays so and fails Validate.
  static Collider Plane(const Vec3& point, const Vec3& normal);
  static Collider Sphere(const Vec3& centre, double radius, bool inside = false);
  static Collider Box(const Vec3& lo, const Vec3& hi, bool inside = false);
  static Collider Polygon(std::vector<Vec3> convexVertices);  // normal from the winding
  static Collider Mesh(std::shared_ptr<const TriangleBvh> bvh);
  static Collider Capsules(std::shared_ptr<const CapsuleBvh> bvh);
  Collider& Restitution(double e) {
    restitution = e;
    return *this;
  }
  Collider& Friction(double mu) {
    friction = mu;
    return *this;
  }
  Collider& Respond(Response r) {
    response = r;
    return *this;
  }
  Collider& Velocity(const Vec3& v) {
    velocity = v;
    return *this;
  }
  bool moving() const { return velocity.x() != 0 || velocity.y() != 0 || velocity.z() != 0; }
  // Moves the solid by d (point, polygon vertices, box corners, the offset
  // of a mesh or capsules).
  void Translate(const Vec3& d);

  // First entry of the path a -> b into the solid. A path that starts inside
  // (a half-space kind only) reports s = 0 at the nearest surface point.
  //
  // The particle's radius r (m, >= 0) counts in every kind: the path is
  // that of the centre of a ball of radius r, tested against the solid
  // grown by r (plane and polygon faces offset by r; a sphere's radius plus
  // r, or minus r inside a bowl; a box's faces moved out by r, or in by r
  // inside a container; a polygon's rim, a triangle's edges and capsules
  // grown by r). The contact point is where the centre is at contact, so
  // the centre stays at least r from the surface. r = 0 is a point.
  // A memo (MeshMemo) serves a mesh's queries; other kinds ignore it.
  bool Intersect(const Vec3& a, const Vec3& b, Contact* c, double r = 0,
                 MeshMemo* memo = nullptr) const;
  // A cheap test that is false only when the path a -> b of a ball of
  // radius r certainly does not touch the collider (the per-particle fast
  // path; for a mesh, a walk down its hierarchy: TriangleBvh::Near).
  [[gnu::always_inline]] bool MayHit(const Vec3& a, const Vec3& b, double r = 0,
                                     const MeshMemo* memo = nullptr) const;
  // Half-space kinds (plane, sphere, box): if x, the centre of a ball of
  // radius r, is inside the solid grown by r, the nearest point of its
  // grown surface (at r from the surface) and its outward normal. Thin
  // kinds return false.
  bool Project(const Vec3& x, Vec3* surface, Vec3* normal, double r = 0) const;

 private:
  // Every kind, out of line; Intersect and Project inline the plane, the
  // kind of most resting contacts.
  bool IntersectAny(const Vec3& a, const Vec3& b, Contact* c, double r, MeshMemo* memo) const;
  bool ProjectAny(const Vec3& x, Vec3* surface, Vec3* normal, double r) const;
  bool IntersectGrownPolygon(const Vec3& a, const Vec3& b, double r, Contact* c) const;
};

// The first field of `c` outside its range (for its kind), or ok.
Status Validate(const Collider& c);

// What RespondToContacts did to a particle.
enum class ContactOutcome {
  kNone,        // its path touched no collider
  kResponded,   // bounced, rested or slid (x and v changed)
  kKilled,      // hit a kKill collider: the caller ends its life
  kStuck,       // hit a kStick collider: the caller makes it immovable
  kUnresolved,  // still met a collider after kMaxContacts contacts in the step:
                // stopped at its last contact point; the caller reports it
};

// Contacts one particle may have in one step before RespondToContacts gives
// up (kUnresolved): only solids that leave no room between them (a point
// inside one is inside another) get there. A particle at 150 m/s in a 1 m
// box at 60 Hz has about 4 a step; an elastic one in a 20-degree wedge at
// most 9 bounces.
constexpr int kMaxContacts = 64;
// Contacts of one step after which every further contact of that step is
// resting or sliding (inelastic): what ends a particle's bouncing in a
// crevice, where it would otherwise bounce without end, nearer and nearer
// the crease.
constexpr int kInelasticContacts = 16;

// Contact response for a particle moving from a (velocity va) to x (velocity
// v) over h seconds. The step's path is the one of constant acceleration
// (v - va) / h from a through x; contacts are found along its chord and
// their time of impact is exact on flat faces (the root of the path against
// the face's plane). A moving collider (Collider::velocity) is where it is
// at the start of the step and moves by h velocity over it: its contacts
// are found and answered in its own frame, in which the path is the
// particle's relative one, so the time of impact and the response (bounce,
// rest, friction) use the relative velocity, exact for a steady
// translation. Any number of contacts a step, until the path meets no
// collider, up to kMaxContacts (then kUnresolved): a bounce reflects the
// path's velocity at the time of impact (normal speed times e, Coulomb
// friction) and goes on along the rest of the path, so at e = 1 the
// integrator's energy is kept; a slower approach is resting or sliding
// contact (the surface takes the inward normal velocity, friction up to mu
// times that from the tangential one; against two surfaces at once the
// particle slides along their crease). A particle that touched anything is
// finally projected out of every half-space solid. x and v are updated.
// `radius` is the particle's (m, >= 0; see Collider::Intersect): its centre
// stays at least that far from every surface.
// `memo`: the particle's MeshMemo (or null), for its mesh queries.
// `skin` (m, >= 0): a particle that starts at most this far above a static
// plane and ends the step behind it rests on it from the start, where it
// is (its contact at the start of the step, at the start itself: the skin
// is the contact), where it would otherwise land on it a moment into the
// step. BulkSystem passes the reach of its rounding to single precision
// (RoundOutside leaves a particle a few ulps above a plane whose height
// with the radius floats cannot represent, and it starts the next step
// there: it then slides at that height, which is a float, with no rounding
// to push it off again); System, 0.
ContactOutcome RespondToContacts(const std::vector<Collider>& colliders, Vec3 a, Vec3 va, Vec3& x,
                                 Vec3& v, double h, double radius = 0, MeshMemo* memo = nullptr,
                                 double skin = 0);

// --- inline ---

inline bool Collider::Intersect(const Vec3& a, const Vec3& b, Contact* c, double r,
                                MeshMemo* memo) const {
  if (kind != Kind::kPlane) return IntersectAny(a, b, c, r, memo);
  // The plane moved out by r.
  const double d1 = normal.dot(b - point) - r;
  if (d1 >= 0) return false;
  const double d0 = normal.dot(a - point) - r;
  c->normal = normal;
  if (d0 <= 0) {  // starts on or below the surface
    c->s = 0;
    c->point = a - d0 * normal;
  } else {
    c->s = d0 / (d0 - d1);
    c->point = a + c->s * (b - a);
    c->point -= (normal.dot(c->point - point) - r) * normal;  // exactly on the plane
  }
  return true;
}

inline bool Collider::Project(const Vec3& x, Vec3* surface, Vec3* n, double r) const {
  if (kind != Kind::kPlane) return ProjectAny(x, surface, n, r);
  const double d = normal.dot(x - point) - r;
  if (d >= 0) return false;
  *surface = x - d * normal;
  *n = normal;
  return true;
}

[[gnu::always_inline]] inline bool Collider::MayHit(const Vec3& a, const Vec3& b, double r,
                                                    const MeshMemo* memo) const {
  switch (kind) {
    case Kind::kPlane:
      return normal.dot(b - point) < r;
    case Kind::kSphere: {
      const double R = inside ? std::max(radius - r, 0.0) : radius + r;
      if (inside) return (b - point).squaredNorm() > R * R || (a - point).squaredNorm() > R * R;
      return ((a.cwiseMin(b) - point).array() <= R).all() &&
             ((a.cwiseMax(b) - point).array() >= -R).all();
    }
    case Kind::kBox:
      if (inside) {
        const Vec3 L = lo.array() + r, H = hi.array() - r;
        return (b.array() < L.array()).any() || (b.array() > H.array()).any() ||
               (a.array() < L.array()).any() || (a.array() > H.array()).any();
      }
      return (a.cwiseMin(b).array() <= hi.array() + r).all() &&
             (a.cwiseMax(b).array() >= lo.array() - r).all();
    case Kind::kPolygon: {
      const double d0 = normal.dot(a - point), d1 = normal.dot(b - point);
      if (r == 0) return (d0 <= 0 && d1 >= 0) || (d0 >= 0 && d1 <= 0);
      return std::min(d0, d1) <= r && std::max(d0, d1) >= -r;
    }
    case Kind::kMesh:
      return mesh && mesh->Near(a - offset, b - offset, r, memo);
    case Kind::kCapsules:
      return true;
  }
  return true;
}

}  // namespace sylva::particles
