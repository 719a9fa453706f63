// cpfg's pixel line widths: a view file's line style `pixels` (`initial
// line width: 2 pixels`, or no width line at all) makes every width a
// number of pixels on the screen, whatever the distance (cpfg draws such
// lines with glLineWidth). PlantGeometry::widthInPixels says so; before
// tessellating, the radii become world units for the view at hand:
//
//   R(p) = r_px / |PixelOffset(view, p, side)|   at each end of each segment,
//
// side being the unit direction across the segment and the line of sight
// (the way a ribbon spreads; PixelsPerUnit where the segment points at
// the eye),
// so a segment drawn 2 pixels wide is 2 pixels wide on screen, near or far,
// and screen-space detail (docs/lod.md) then draws it as a camera-facing
// ribbon (under 1.5 px in radius) or a coverage line (under 1 px wide).
// Without a view (an export at uniform detail) a pixel is 1/kNominalPixels
// of the plant's largest extent, as in a picture kNominalPixels high.
#pragma once

#include "mesh/plant_geometry.h"
#include "mesh/screen_detail.h"

namespace sylva::mesh {

inline constexpr double kNominalPixels = 1000;

// `g` with its segment radii in world units for `view` (null: the nominal
// scale above) and widthInPixels cleared. Segments with an end at or
// behind the eye's plane get radius 0 there. A geometry whose widths are
// not pixels is returned unchanged.
PlantGeometry ResolvePixelWidths(const PlantGeometry& g, const ScreenView* view);

}  // namespace sylva::mesh
