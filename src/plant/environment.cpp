#include "plant/environment.h"

#include <cmath>
#include <string>

#include "plant/ground_environment.h"
#include "plant/light_grid.h"
#include "plant/shape_environment.h"

namespace sylva::plant {
namespace {

using Item = lsys::EnvironmentStatement::Item;

Diagnostic ErrorAt(const lsys::Grammar& g, const SourceLoc& loc, std::string message, int length) {
  return MakeError(loc, std::move(message), length, g.SourceLine(loc));
}

bool AllFinite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x) || std::abs(x) > 1e15) return false;
  return true;
}

Expected<std::unique_ptr<Environment>> MakeShape(const lsys::EnvironmentStatement& st,
                                                 const lsys::Grammar& g) {
  const char* kShapes =
      "box(x0, y0, z0, x1, y1, z1), sphere(x, y, z, r) or ellipsoid(x, y, z, rx, ry, rz)";
  if (st.items.size() != 1 || !st.items[0].call) {
    const SourceLoc& loc = st.items.size() > 1 ? st.items[1].loc : st.loc;
    return ErrorAt(g, loc, std::string("'environment: shape' takes one shape: ") + kShapes, 1);
  }
  const Item& it = st.items[0];
  const std::vector<double>& v = it.values;
  const int len = int(it.name.size());
  auto count = [&](size_t n) -> std::optional<Diagnostic> {
    if (v.size() == n && AllFinite(v)) return std::nullopt;
    return ErrorAt(g, it.loc,
                   "'" + it.name + "' takes " + std::to_string(n) + " finite numbers; it has " +
                       std::to_string(v.size()) + (AllFinite(v) ? "" : ", not all finite"),
                   len);
  };
  ShapeDef def;
  if (it.name == "box") {
    if (auto e = count(6)) return *e;
    def.kind = ShapeDef::Kind::kBox;
    def.a = Vec3(std::min(v[0], v[3]), std::min(v[1], v[4]), std::min(v[2], v[5]));
    def.b = Vec3(std::max(v[0], v[3]), std::max(v[1], v[4]), std::max(v[2], v[5]));
  } else if (it.name == "sphere") {
    if (auto e = count(4)) return *e;
    if (!(v[3] > 0)) return ErrorAt(g, it.loc, "the sphere's radius must be positive", len);
    def.kind = ShapeDef::Kind::kSphere;
    def.a = Vec3(v[0], v[1], v[2]);
    def.b = Vec3(v[3], v[3], v[3]);
  } else if (it.name == "ellipsoid") {
    if (auto e = count(6)) return *e;
    if (!(v[3] > 0 && v[4] > 0 && v[5] > 0))
      return ErrorAt(g, it.loc, "the ellipsoid's radii must be positive", len);
    def.kind = ShapeDef::Kind::kEllipsoid;
    def.a = Vec3(v[0], v[1], v[2]);
    def.b = Vec3(v[3], v[4], v[5]);
  } else {
    return ErrorAt(g, it.loc, "unknown shape '" + it.name + "': Sylva has " + kShapes, len);
  }
  return std::unique_ptr<Environment>(new ShapeEnvironment(def));
}

Expected<std::unique_ptr<Environment>> MakeLight(const lsys::EnvironmentStatement& st,
                                                 const lsys::Grammar& g) {
  LightDef def;
  for (const Item& it : st.items) {
    const int len = int(it.name.size());
    if (it.call) {
      if (it.name != "box") {
        return ErrorAt(g, it.loc,
                       "unknown obstacle '" + it.name +
                           "' in 'environment: light': Sylva has box(x0, y0, z0, x1, y1, z1)",
                       len);
      }
      const auto& v = it.values;
      if ((v.size() != 6 && v.size() != 7) || !AllFinite(v)) {
        return ErrorAt(g, it.loc,
                       "'box' takes 6 or 7 finite numbers: x0, y0, z0, x1, y1, z1 and the shadow "
                       "of each voxel",
                       len);
      }
      if (v.size() == 7 && !(v[6] > 0 && v[6] <= 1e6))
        return ErrorAt(g, it.loc, "a box's shadow must be in (0, 1e6]", len);
      def.walls.push_back(
          LightBox{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5]), v.size() == 7 ? v[6] : -1});
      continue;
    }
    if (!it.keyValue) {
      return ErrorAt(g, it.loc,
                     "unknown word '" + it.name +
                         "' in 'environment: light': expected cell=, depth=, shadow=, falloff= "
                         "or box(...)",
                     len);
    }
    const double x = it.values[0];
    if (it.name == "cell") {
      if (!(x > 0 && x <= 1e6)) return ErrorAt(g, it.loc, "cell must be in (0, 1e6]", len);
      def.cell = x;
    } else if (it.name == "depth") {
      if (!(x >= 0 && x <= 64 && x == std::floor(x)))
        return ErrorAt(g, it.loc, "depth must be a whole number from 0 to 64", len);
      def.depth = int(x);
    } else if (it.name == "shadow") {
      if (!(x > 0 && x <= 1e6)) return ErrorAt(g, it.loc, "shadow must be in (0, 1e6]", len);
      def.shadow = x;
    } else if (it.name == "falloff") {
      if (!(x >= 1 && x <= 1e6)) return ErrorAt(g, it.loc, "falloff must be in [1, 1e6]", len);
      def.falloff = x;
    } else {
      return ErrorAt(g, it.loc,
                     "unknown key '" + it.name +
                         "' in 'environment: light': Sylva has cell=, depth=, shadow=, falloff=",
                     len);
    }
  }
  return std::unique_ptr<Environment>(new LightEnvironment(def));
}

}  // namespace

Expected<std::unique_ptr<Environment>> MakeEnvironment(const lsys::EnvironmentStatement& st,
                                                       const lsys::Grammar& g,
                                                       const Ground* ground) {
  if (st.kind == "shape") return MakeShape(st, g);
  if (st.kind == "light") return MakeLight(st, g);
  if (st.kind == "terrain") {
    if (!st.items.empty()) {
      return ErrorAt(g, st.items[0].loc, "'environment: terrain' takes nothing after it",
                     int(st.items[0].name.size()));
    }
    return std::unique_ptr<Environment>(
        new GroundEnvironment(ground && ground->height && ground->normal ? *ground : FlatGround()));
  }
  return ErrorAt(g, st.loc,
                 "unknown environment '" + st.kind + "': Sylva has 'shape', 'light' and 'terrain'",
                 int(st.kind.size()));
}

}  // namespace sylva::plant
