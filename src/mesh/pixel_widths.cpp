#include "mesh/pixel_widths.h"

#include <algorithm>
#include <cmath>

namespace sylva::mesh {
namespace {

// World units per pixel at p across a line along `axis`: measured along
// the side direction (across the axis and the line of sight), as a ribbon
// spreads (docs/lod.md); PixelsPerUnit's largest stretch where the axis
// points at the eye. 0 where the view cannot say (at or behind the eye's
// plane).
double UnitsPerPixel(const ScreenView& view, const Vec3& p, const Vec3& axis) {
  const Vec3 side = axis.cross(TowardEye(view, p));
  double ppu = 0;
  if (side.norm() > 1e-9 * std::max(axis.norm(), 1e-300))
    ppu = PixelOffset(view, p, side.normalized()).norm();
  else
    ppu = PixelsPerUnit(view, p);
  return std::isfinite(ppu) && ppu > 0 ? 1.0 / ppu : 0.0;
}

}  // namespace

PlantGeometry ResolvePixelWidths(const PlantGeometry& g, const ScreenView* view) {
  PlantGeometry out = g;
  if (!g.widthInPixels) return out;
  out.widthInPixels = false;
  if (view) {
    // A line is at least one pixel wide, as cpfg's pixel lines are (OpenGL
    // draws a glLineWidth under 1 one pixel wide): L-studio's cloud_I(line)
    // asks for 0.05 pixels and was drawn as faint coverage lines.
    for (Segment& s : out.segments) {
      const Vec3 axis = s.end - s.start;
      s.radiusStart =
          float(std::max(double(s.radiusStart), 0.5) * UnitsPerPixel(*view, s.start, axis));
      s.radiusEnd = float(std::max(double(s.radiusEnd), 0.5) * UnitsPerPixel(*view, s.end, axis));
    }
    return out;
  }
  const double extent = (g.boundsMax - g.boundsMin).maxCoeff();
  const double unit = extent > 0 && std::isfinite(extent) ? extent / kNominalPixels : 0.0;
  for (Segment& s : out.segments) {
    s.radiusStart = float(s.radiusStart * unit);
    s.radiusEnd = float(s.radiusEnd * unit);
  }
  return out;
}

}  // namespace sylva::mesh
